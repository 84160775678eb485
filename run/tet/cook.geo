// Cook's membrane: the tapered panel (0,0), (48,44), (48,60), (0,44), clamped on x = 0 and
// sheared on x = 48, as a slab of thickness T in z whose two z faces the scene holds in z
// (plane strain). Set on the command line:
//   -setnumber n N     elements along each side of the panel
//   -setnumber tet 1   tetrahedra (an unstructured mesh of element size 16/N, the slab one
//                      element thick); 0 (default): hexahedra, transfinite and one layer
//   -setnumber order 2 10-node tetrahedra written by Gmsh (default 1: 4-node, which the
//                      solver completes to 10 nodes)
// Physical groups: volume "panel"; surfaces "clamp" (x = 0) and "load" (x = 48).
DefineConstant[ n = 4, tet = 0, order = 1 ];
h = 16 / n;
T = (tet > 0) ? h : 1;

Point(1) = {0, 0, 0};
Point(2) = {48, 44, 0};
Point(3) = {48, 60, 0};
Point(4) = {0, 44, 0};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};

If (tet > 0)
  Mesh.MeshSizeMin = h;
  Mesh.MeshSizeMax = h;
  out[] = Extrude {0, 0, T} { Surface{1}; };
  Mesh.ElementOrder = order;
  Mesh.SecondOrderLinear = 1;
Else
  Transfinite Curve{1, 2, 3, 4} = n + 1;
  Transfinite Surface{1};
  Recombine Surface{1};
  out[] = Extrude {0, 0, T} { Surface{1}; Layers{1}; Recombine; };
EndIf
// out[0]: the top surface, out[1]: the volume, out[2..5]: the sides on curves 1..4.
Physical Volume("panel") = {out[1]};
Physical Surface("clamp") = {out[5]};
Physical Surface("load") = {out[3]};
