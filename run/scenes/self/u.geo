// A thick U (horseshoe) in the x-y plane, one element thick in z, all hexahedra
// (transfinite, recombined, extruded by one layer), symmetric about x = 0: a base
// x in [-2, 2], y in [0, 1] and two arms x in [-2, -g] and [g, 2], y in [1, 4], with a gap
// of 2g = 0.2 between them. half = 1 keeps the part x <= 0 only (the half model).
// Regenerate the .msh files with run/scenes/self/make_meshes.
DefineConstant[ half = 0 ];
g = 0.1;   // half the gap between the arms
t = 0.5;   // thickness in z
na = 6;    // elements across an arm (x)
nb = 3;    // elements through the base (y)
nh = 12;   // elements along an arm (y)

Point(1) = {-2, 0, 0}; Point(2) = {-g, 0, 0}; Point(3) = {0, 0, 0};
Point(6) = {-2, 1, 0}; Point(7) = {-g, 1, 0}; Point(8) = {0, 1, 0};
Point(11) = {-2, 4, 0}; Point(12) = {-g, 4, 0};
Line(1) = {1, 2}; Line(2) = {2, 3};
Line(5) = {6, 7}; Line(6) = {7, 8};
Line(9) = {11, 12};
Line(11) = {1, 6}; Line(12) = {2, 7}; Line(13) = {3, 8};
Line(16) = {6, 11}; Line(17) = {7, 12};
Curve Loop(1) = {1, 12, -5, -11}; Plane Surface(1) = {1};  // base, left
Curve Loop(2) = {2, 13, -6, -12}; Plane Surface(2) = {2};  // base, middle left
Curve Loop(5) = {5, 17, -9, -16}; Plane Surface(5) = {5};  // left arm
Transfinite Curve{1, 5, 9} = na + 1;
Transfinite Curve{2, 6} = 2;
Transfinite Curve{11, 12, 13} = nb + 1;
Transfinite Curve{16, 17} = nh + 1;
surfaces[] = {1, 2, 5};
If (half == 0)
  Point(4) = {g, 0, 0}; Point(5) = {2, 0, 0};
  Point(9) = {g, 1, 0}; Point(10) = {2, 1, 0};
  Point(13) = {g, 4, 0}; Point(14) = {2, 4, 0};
  Line(3) = {3, 4}; Line(4) = {4, 5};
  Line(7) = {8, 9}; Line(8) = {9, 10};
  Line(10) = {13, 14};
  Line(14) = {4, 9}; Line(15) = {5, 10};
  Line(18) = {9, 13}; Line(19) = {10, 14};
  Curve Loop(3) = {3, 14, -7, -13}; Plane Surface(3) = {3};  // base, middle right
  Curve Loop(4) = {4, 15, -8, -14}; Plane Surface(4) = {4};  // base, right
  Curve Loop(6) = {8, 19, -10, -18}; Plane Surface(6) = {6};  // right arm
  Transfinite Curve{4, 8, 10} = na + 1;
  Transfinite Curve{3, 7} = 2;
  Transfinite Curve{14, 15} = nb + 1;
  Transfinite Curve{18, 19} = nh + 1;
  surfaces[] += {3, 4, 6};
EndIf
Transfinite Surface{surfaces[]};
Recombine Surface{surfaces[]};
out[] = Extrude {0, 0, t} { Surface{surfaces[]}; Layers{1}; Recombine; };
// Extrude lists, per surface, the top surface, then the volume, then the sides.
volumes[] = {};
For i In {0 : #surfaces[] - 1}
  volumes[] += out[6 * i + 1];
EndFor
Physical Volume("u") = {volumes[]};
