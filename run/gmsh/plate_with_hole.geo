// A plate with a circular hole through it, built with Gmsh's OpenCASCADE kernel: a box
// (L x W x T) less a cylinder (radius R) through its thickness at its centre. Gmsh meshes
// it with tetrahedra of size h and splits each into four hexahedra
// (Mesh.SubdivisionAlgorithm = 2): an all-hexahedral mesh without structure, its elements
// of every shape. Units: mm. Regenerate the .msh files with run/gmsh/make_examples; the
// scene is run/scenes/bench/plate_with_hole.toml.
// Physical groups: volume "plate"; surfaces "left" (x = 0), "right" (x = L).

SetFactory("OpenCASCADE");

// Refinement factor (run/gmsh/make_examples sets it with -setnumber f N; 1 gives the
// checked-in mesh): the element size is divided by it.
DefineConstant[ f = 1 ];

L = 100;     // length (x)
W = 50;      // width (y)
T = 10;      // thickness (z)
R = 10;      // hole radius
h = 4.9 / f; // element size

Box(1) = {0, 0, 0, L, W, T};
Cylinder(2) = {L / 2, W / 2, -1, 0, 0, T + 2, R};
BooleanDifference(3) = { Volume{1}; Delete; }{ Volume{2}; Delete; };

Mesh.MeshSizeMin = h;
Mesh.MeshSizeMax = h;
Mesh.SubdivisionAlgorithm = 2;
Mesh.SaveAll = 0;

e = 1e-4;
left[] = Surface In BoundingBox{-e, -e, -e, e, W + e, T + e};
right[] = Surface In BoundingBox{L - e, -e, -e, L + e, W + e, T + e};
Physical Volume("plate") = {3};
Physical Surface("left") = {left[]};
Physical Surface("right") = {right[]};
