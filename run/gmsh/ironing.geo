// Ironing: a rigid half-cylinder die (radius R, axis along z, curved side down) over a
// soft slab, one element thick in z, all hexahedra (transfinite, recombined, extruded by
// one layer). The die's lowest point touches the slab's top y = 0 at x = 0. The slab's
// mesh is uniform along the path the die is dragged. Regenerate the .msh files with
// run/gmsh/make_examples.

R = 1;       // die radius
T = 0.25;    // thickness in z (one element; the scene makes it plane strain)
L0 = -2;     // slab from x = L0
L1 = 6;      // to x = L1
H = 1;       // slab thickness
r = 0.45*R;  // half-width of the die's inner rectangle (its height too)

DefineConstant[ f = 1 ];

nb = 12*f;   // elements along the die's bottom arc (90 degrees) and inner rectangle
ns = 3*f;    // elements along each 45-degree side arc and the rectangle's sides
nr = 3*f;    // elements from the inner rectangle out to the arc
nl = 40*f;   // elements along the slab
nh = 5*f;    // elements through the slab

c = R*Sqrt(0.5);
Point(1) = {0, R, 0};
Point(2) = {-R, R, 0};
Point(3) = {R, R, 0};
Point(4) = {-c, R - c, 0};
Point(5) = {c, R - c, 0};
Point(6) = {-r, R, 0};
Point(7) = {r, R, 0};
Point(8) = {r, R - r, 0};
Point(9) = {-r, R - r, 0};

Circle(1) = {2, 1, 4};
Circle(2) = {4, 1, 5};
Circle(3) = {5, 1, 3};
Line(4) = {6, 2};
Line(5) = {6, 7};
Line(6) = {7, 3};
Line(7) = {9, 4};
Line(8) = {8, 5};
Line(9) = {9, 8};
Line(10) = {6, 9};
Line(11) = {7, 8};

Curve Loop(1) = {5, 11, -9, -10};
Curve Loop(2) = {9, 8, -2, -7};
Curve Loop(3) = {-4, 10, 7, -1};
Curve Loop(4) = {6, -3, -8, -11};
Plane Surface(1) = {1};
Plane Surface(2) = {2};
Plane Surface(3) = {3};
Plane Surface(4) = {4};

Transfinite Curve {2, 9, 5} = nb + 1;
Transfinite Curve {1, 3, 10, 11} = ns + 1;
Transfinite Curve {4, 6, 7, 8} = nr + 1;

Point(11) = {L0, 0, 0};
Point(12) = {L1, 0, 0};
Point(13) = {L1, -H, 0};
Point(14) = {L0, -H, 0};
Line(21) = {11, 12};
Line(22) = {12, 13};
Line(23) = {13, 14};
Line(24) = {14, 11};
Curve Loop(11) = {21, 22, 23, 24};
Plane Surface(11) = {11};
Transfinite Curve {21, 23} = nl + 1;
Transfinite Curve {22, 24} = nh + 1;

Transfinite Surface {1, 2, 3, 4, 11};
Recombine Surface {1, 2, 3, 4, 11};

die1[] = Extrude {0, 0, T} { Surface{1}; Layers{1}; Recombine; };
die2[] = Extrude {0, 0, T} { Surface{2}; Layers{1}; Recombine; };
die3[] = Extrude {0, 0, T} { Surface{3}; Layers{1}; Recombine; };
die4[] = Extrude {0, 0, T} { Surface{4}; Layers{1}; Recombine; };
slab[] = Extrude {0, 0, T} { Surface{11}; Layers{1}; Recombine; };

Physical Volume("die") = {die1[1], die2[1], die3[1], die4[1]};
Physical Volume("slab") = {slab[1]};
// Side surfaces in the order of the base surface's curves: loop 2 = {9, 8, 2, 7},
// loop 3 = {4, 10, 7, 1}, loop 4 = {6, 3, 8, 11}; loop 11 = {21 (top), 22, 23 (bottom), 24}.
Physical Surface("die_arc") = {die2[4], die3[5], die4[3]};
Physical Surface("slab_top") = {slab[2]};
Physical Surface("slab_bottom") = {slab[4]};
