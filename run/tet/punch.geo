// The flat punch of run/scenes/plasticity/punch_40.toml on tetrahedra: the block
// (0,0)-(6,6) in x and y, a slab of thickness T in z whose nodes the scene holds in z
// (plane strain), half model (symmetry at x = 0), the punch over 0 <= x <= 1 on y = 6.
// Set on the command line:
//   -setnumber n N   element size 6/N away from the punch's edge
//   -setnumber r R   the size at the punch's edge (1, 6) is 6/(N R) (default 4), growing
//                    linearly to 6/N at distance 2
// The slab is one element thick at the finest size (T = 6/(N R)). Gmsh writes 4-node
// tetrahedra (the solver completes them to 10 nodes) or, with -setnumber order 2, 10-node.
// Physical groups: volume "block".
DefineConstant[ n = 10, r = 4, order = 1 ];
h = 6 / n;
hf = h / r;
T = hf;

Point(1) = {0, 0, 0, h};
Point(2) = {6, 0, 0, h};
Point(3) = {6, 6, 0, h};
Point(4) = {1, 6, 0, hf};
Point(5) = {0, 6, 0, h};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 5};
Line(5) = {5, 1};
Curve Loop(1) = {1, 2, 3, 4, 5};
Plane Surface(1) = {1};

Field[1] = Distance;
Field[1].PointsList = {4};
Field[2] = Threshold;
Field[2].InField = 1;
Field[2].SizeMin = hf;
Field[2].SizeMax = h;
Field[2].DistMin = 0;
Field[2].DistMax = 2;
Background Field = 2;
Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromPoints = 0;

out[] = Extrude {0, 0, T} { Surface{1}; };
Mesh.ElementOrder = order;
Mesh.SecondOrderLinear = 1;
Physical Volume("block") = {out[1]};
