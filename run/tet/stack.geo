// Two unit cubes stacked along z, meshed independently (their interface z = 1 does not
// share nodes): the lower [0,1]^2 x [0,1] of n^3 structured hexahedra (or of tetrahedra of
// size hl when lower_tet = 1), the upper [0,1]^2 x [1,2] of tetrahedra of size h (4-node:
// the solver completes them to 10 nodes). The contact patch tests of tests/tet_contact.rs
// and mpi-tests/tet_on_hex.toml. Set on the command line with -setnumber NAME VALUE.
// Physical groups: volumes "lower", "upper"; surfaces "lower_bottom" (z = 0),
// "lower_top" (z = 1), "upper_bottom" (z = 1), "upper_top" (z = 2).
DefineConstant[ n = 4, h = 0.3, lower_tet = 0, hl = 0.22 ];
SetFactory("OpenCASCADE");
Box(1) = {0, 0, 0, 1, 1, 1};
Box(2) = {0, 0, 1, 1, 1, 1};
If (lower_tet == 0)
  Transfinite Curve{1:12} = n + 1;
  Transfinite Surface{1:6};
  Recombine Surface{1:6};
  Transfinite Volume{1};
Else
  MeshSize{ PointsOf{ Volume{1}; } } = hl;
EndIf
MeshSize{ PointsOf{ Volume{2}; } } = h;
Physical Volume("lower") = {1};
Physical Volume("upper") = {2};
Physical Surface("lower_bottom") = {5};
Physical Surface("lower_top") = {6};
Physical Surface("upper_bottom") = {11};
Physical Surface("upper_top") = {12};
