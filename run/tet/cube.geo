// The unit cube [0,1]^3 meshed with tetrahedra (unstructured, element size h). Set on the
// command line: -setnumber h H (default 0.25), -setnumber order 2 for 10-node tetrahedra
// written by Gmsh (default 1: 4-node, which the solver completes to 10 nodes).
// Physical groups: volume "cube"; surfaces "bottom" (z = 0) and "top" (z = 1).
DefineConstant[ h = 0.25, order = 1 ];
SetFactory("OpenCASCADE");
Box(1) = {0, 0, 0, 1, 1, 1};
Mesh.MeshSizeMin = h;
Mesh.MeshSizeMax = h;
Mesh.ElementOrder = order;
Mesh.SecondOrderLinear = 1;
Physical Volume("cube") = {1};
Physical Surface("bottom") = {5};
Physical Surface("top") = {6};
