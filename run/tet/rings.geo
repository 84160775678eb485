// Two rings meshed apart on one circle (tests/adjust.rs, mpi-tests/rings.toml): a quarter
// of an inner ring a < r < c inside an outer ring c < r < b, 1 mm thick in z, each its own
// volume (not fragmented: the faces at r = c do not share nodes), meshed with tetrahedra of
// size hi and ho. Physical groups: volumes "inner", "outer"; surfaces "bore" (r = a),
// "inner_c" (the inner ring's r = c), "outer_c" (the outer ring's r = c). Set on the
// command line with -setnumber NAME VALUE.
DefineConstant[ hi = 0.5, ho = 0.7 ];
SetFactory("OpenCASCADE");
a = 5; c = 7.5; b = 10; T = 1;
Cylinder(1) = {0, 0, 0, 0, 0, T, c, Pi/2};
Cylinder(2) = {0, 0, 0, 0, 0, T, a, Pi/2};
BooleanDifference(3) = { Volume{1}; Delete; }{ Volume{2}; Delete; };
Cylinder(4) = {0, 0, 0, 0, 0, T, b, Pi/2};
Cylinder(5) = {0, 0, 0, 0, 0, T, c, Pi/2};
BooleanDifference(6) = { Volume{4}; Delete; }{ Volume{5}; Delete; };
e = 1e-3;
Physical Volume("inner") = {3};
Physical Volume("outer") = {6};
ib[] = Boundary{ Volume{3}; };
bore[] = Surface In BoundingBox{-e, -e, -e, a + e, a + e, T + e};
cand[] = Surface In BoundingBox{-e, -e, -e, c + e, c + e, T + e};
xs[] = Surface In BoundingBox{-e, -e, -e, e, b + e, T + e};
ys[] = Surface In BoundingBox{-e, -e, -e, b + e, e, T + e};
z0[] = Surface In BoundingBox{-e, -e, -e, b + e, b + e, e};
z1[] = Surface In BoundingBox{-e, -e, T - e, b + e, b + e, T + e};
cand[] -= {xs[], ys[], z0[], z1[], bore[]};
inner_c[] = {}; outer_c[] = {};
For i In {0 : #cand[] - 1}
  found = 0;
  For j In {0 : #ib[] - 1}
    If (Abs(ib[j]) == cand[i])
      found = 1;
    EndIf
  EndFor
  If (found)
    inner_c[] += cand[i];
  Else
    outer_c[] += cand[i];
  EndIf
EndFor
Physical Surface("bore") = {bore[]};
Physical Surface("inner_c") = {inner_c[]};
Physical Surface("outer_c") = {outer_c[]};
MeshSize{ PointsOf{ Volume{3}; } } = hi;
MeshSize{ PointsOf{ Volume{6}; } } = ho;
