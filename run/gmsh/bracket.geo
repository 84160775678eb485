// An L-shaped steel bracket bolted onto a base plate, built with Gmsh's OpenCASCADE kernel:
// the foot (Lf x t x b) and the upright arm (t x H x b) joined by a Boolean union, the inner
// corner filleted (radius rf), a bolt hole (radius rh) drilled through the foot by a Boolean
// difference, and the ring under the bolt head (rh < r < rw) split off by Boolean fragments
// so that its top face is a surface of its own (the "washer", where the scene holds the
// bolt). The bracket is meshed with 4-node tetrahedra of size h (the solver completes them
// to 10-node ones), finer (hf) along the bend; the base plate under it is a structured block
// of hexahedra. The foot is g = 1 micrometre above the plate's top (touching, every node of
// the foot's bottom would start in contact and be released a few per contact update): two
// separate meshes, their nodes not shared, for contact. Units: mm. Regenerate the .msh
// files with run/gmsh/make_examples; run/examples/bracket.toml is the scene.
// Physical groups: volumes "bracket", "plate"; surfaces "foot_bottom" (y = 0), "washer"
// (the ring's top, y = t), "arm_top" (y = H), "plate_top" (y = -g), "plate_bottom"
// (y = -g - tp).

SetFactory("OpenCASCADE");

// Refinement factor (run/gmsh/make_examples sets it with -setnumber f N; 1 gives the
// checked-in mesh): every element size below is divided by it, every division count
// multiplied.
DefineConstant[ f = 1 ];

t = 5;       // thickness of the foot and of the arm
b = 20;      // width (z)
Lf = 40;     // length of the foot (x)
H = 40;      // height of the arm (y)
rf = 2;      // fillet radius of the inner corner
xb = 25;     // bolt axis (x, z) = (xb, b / 2)
rh = 3.3;    // bolt hole radius (an M6 clearance hole)
rw = 6;      // radius of the bolt head's bearing ring
h = 5 / f;   // element size of the bracket
hf = 3 / f;  // element size along the bend
// The base plate: x from -px to Lf + px, z from -pz to b + pz, y from -tp - g to -g.
px = 10; pz = 5; tp = 6;
g = 1e-3;    // the gap between the foot and the plate
nx = 12 * f; ny = 2 * f; nz = 6 * f;

Box(1) = {0, 0, 0, Lf, t, b};
Box(2) = {0, 0, 0, t, H, b};
BooleanUnion(3) = { Volume{1}; Delete; }{ Volume{2}; Delete; };
e = 1e-4;
corner[] = Curve In BoundingBox{t - e, t - e, -e, t + e, t + e, b + e};
filleted[] = Fillet{3}{corner[]}{rf};
Cylinder(10) = {xb, -1, b / 2, 0, t + 2, 0, rh};
BooleanDifference(11) = { Volume{filleted[0]}; Delete; }{ Volume{10}; Delete; };
Cylinder(12) = {xb, 0, b / 2, 0, t, 0, rw};
Cylinder(13) = {xb, 0, b / 2, 0, t, 0, rh};
BooleanDifference(14) = { Volume{12}; Delete; }{ Volume{13}; Delete; };
pieces[] = BooleanFragments{ Volume{11}; Delete; }{ Volume{14}; Delete; };

Box(20) = {-px, -tp - g, -pz, Lf + 2 * px, tp, b + 2 * pz};
// The plate's twelve edges, each found in a thin box along it, and its division count.
For i In {0:1}
  For j In {0:1}
    cx[] = Curve In BoundingBox{-px - e, -g - tp + i * tp - e, -pz + j * (b + 2 * pz) - e,
                                Lf + px + e, -g - tp + i * tp + e, -pz + j * (b + 2 * pz) + e};
    Transfinite Curve{cx[]} = nx + 1;
    cy[] = Curve In BoundingBox{-px + i * (Lf + 2 * px) - e, -g - tp - e,
                                -pz + j * (b + 2 * pz) - e, -px + i * (Lf + 2 * px) + e,
                                -g + e, -pz + j * (b + 2 * pz) + e};
    Transfinite Curve{cy[]} = ny + 1;
    cz[] = Curve In BoundingBox{-px + i * (Lf + 2 * px) - e, -g - tp + j * tp - e, -pz - e,
                                -px + i * (Lf + 2 * px) + e, -g - tp + j * tp + e, b + pz + e};
    Transfinite Curve{cz[]} = nz + 1;
  EndFor
EndFor
plate_faces[] = Boundary{ Volume{20}; };
Transfinite Surface{plate_faces[]};
Recombine Surface{plate_faces[]};
Transfinite Volume{20};

bracket[] = Volume In BoundingBox{-e, -e, -e, Lf + e, H + e, b + e};
// Finer along the bend: the fillet's points and the foot's and the arm's corners near it.
MeshSize{ PointsOf{ Volume{bracket[]}; } } = h;
bend[] = Point In BoundingBox{-e, -e, -e, t + rf + e, t + rf + e, b + e};
MeshSize{ bend[] } = hf;

Physical Volume("bracket") = {bracket[]};
Physical Volume("plate") = {20};
foot_bottom[] = Surface In BoundingBox{-e, -e, -e, Lf + e, e, b + e};
Physical Surface("foot_bottom") = {foot_bottom[]};
Physical Surface("washer") = Surface In BoundingBox{xb - rw - e, t - e, b / 2 - rw - e,
                                                    xb + rw + e, t + e, b / 2 + rw + e};
Physical Surface("arm_top") = Surface In BoundingBox{-e, H - e, -e, t + e, H + e, b + e};
plate_top[] = Surface In BoundingBox{-px - e, -g - e, -pz - e, Lf + px + e, -g + e, b + pz + e};
plate_top[] -= {foot_bottom[]}; // (with g = 0 the box would hold the foot's bottom too)
Physical Surface("plate_top") = {plate_top[]};
Physical Surface("plate_bottom") = Surface In BoundingBox{-px - e, -g - tp - e, -pz - e,
                                                          Lf + px + e, -g - tp + e, b + pz + e};
