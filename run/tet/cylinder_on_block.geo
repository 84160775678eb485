// The Hertz cylinder on a block (run/examples/cylinder_on_block.toml's geometry: a
// half-cylinder R = 10 mm on a 40 x 20 mm block, 1 mm thick in z, touching along the line
// x = y = 0) meshed with tetrahedra (4-node: the solver completes them to 10 nodes), refined
// toward the contact line: element size hmin + g * (distance from the line), at most hmax.
// Physical groups as the hexahedral mesh's (run/gmsh/cylinder_on_block.geo): volumes
// "cylinder", "block"; surfaces "cylinder_top", "cylinder_arc", "block_top",
// "block_bottom". Set on the command line with -setnumber NAME VALUE.
DefineConstant[ hmin = 0.25, g = 0.3, hmax = 4 ];
SetFactory("OpenCASCADE");
R = 10; T = 1; W = 20; H = 20;
Cylinder(1) = {0, R, 0, 0, 0, T, R};
Box(2) = {-R - 1, R, -1, 2 * R + 2, R + 1, T + 2};
BooleanDifference(3) = { Volume{1}; Delete; }{ Volume{2}; Delete; };
Box(4) = {-W, -H, 0, 2 * W, H, T};
e = 1e-3;
top[] = Surface In BoundingBox{-R - e, R - e, -e, R + e, R + e, T + e};
z0[] = Surface In BoundingBox{-R - e, -e, -e, R + e, R + e, e};
z1[] = Surface In BoundingBox{-R - e, -e, T - e, R + e, R + e, T + e};
arc[] = Surface In BoundingBox{-R - e, -e, -e, R + e, R + e, T + e};
arc[] -= {top[], z0[], z1[]};
Physical Volume("cylinder") = {3};
Physical Volume("block") = {4};
Physical Surface("cylinder_top") = {top[]};
Physical Surface("cylinder_arc") = {arc[]};
Physical Surface("block_top") = Surface In BoundingBox{-W - e, -e, -e, W + e, e, T + e};
Physical Surface("block_bottom") = Surface In BoundingBox{-W - e, -H - e, -e, W + e, -H + e, T + e};
Field[1] = MathEval;
Field[1].F = Sprintf("Min(%g, %g + %g * Sqrt(x * x + y * y))", hmax, hmin, g);
Background Field = 1;
Mesh.MeshSizeFromPoints = 0;
Mesh.MeshSizeFromCurvature = 0;
Mesh.MeshSizeExtendFromBoundary = 0;
