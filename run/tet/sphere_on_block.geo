// A quarter of a sphere pressed on a block (Hertz's point contact), for the symmetry
// planes x = 0 and z = 0: the lower half of a sphere R = 10 mm centred at (0, R, 0),
// touching the block's top y = 0 at the origin; the block 20 x 20 x 20 mm below it.
// Meshed with tetrahedra (4-node: the solver completes them to 10 nodes; -order 2 for
// Gmsh's own 10-node ones), refined toward the contact point: element size
// hmin + g * (distance from the origin), at most hmax. Physical groups: volumes "sphere",
// "block"; surfaces "sphere_top" (the flat cut through the centre, where the load goes),
// "sphere_surface" (the spherical part), "block_top", "block_bottom". Set on the command
// line with -setnumber NAME VALUE.
DefineConstant[ hmin = 0.2, g = 0.3, hmax = 4 ];
SetFactory("OpenCASCADE");
R = 10; W = 20; H = 20;
Sphere(1) = {0, R, 0, R};
Box(2) = {0, 0, 0, R, R, R};
BooleanIntersection(3) = { Volume{1}; Delete; }{ Volume{2}; Delete; };
Box(4) = {0, -H, 0, W, H, W};
e = 1e-3;
top[] = Surface In BoundingBox{-e, R - e, -e, R + e, R + e, R + e};
x0[] = Surface In BoundingBox{-e, -e, -e, e, R + e, R + e};
z0[] = Surface In BoundingBox{-e, -e, -e, R + e, R + e, e};
all[] = Surface In BoundingBox{-e, -e, -e, R + e, R + e, R + e};
all[] -= {x0[], z0[], top[]};
Physical Volume("sphere") = {3};
Physical Volume("block") = {4};
Physical Surface("sphere_top") = {top[]};
Physical Surface("sphere_surface") = {all[]};
Physical Surface("block_top") = Surface In BoundingBox{-e, -e, -e, W + e, e, W + e};
Physical Surface("block_bottom") = Surface In BoundingBox{-e, -H - e, -e, W + e, -H + e, W + e};
Field[1] = MathEval;
Field[1].F = Sprintf("Min(%g, %g + %g * Sqrt(x * x + y * y + z * z))", hmax, hmin, g);
Background Field = 1;
Mesh.MeshSizeFromPoints = 0;
Mesh.MeshSizeFromCurvature = 0;
Mesh.MeshSizeExtendFromBoundary = 0;
