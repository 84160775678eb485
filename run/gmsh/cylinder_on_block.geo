// A half-cylinder (radius R, axis along z, curved side down) resting on a block, one
// element thick in z, all hexahedra: every surface is transfinite and recombined, then
// extruded by one layer. Units: mm. The cylinder touches the block along the line
// x = 0, y = 0; the mesh is symmetric about x = 0 and is finest there, where the
// contact patch forms. Regenerate the .msh files with run/gmsh/make_examples.
// Only the elements of physical groups are saved: the hexahedra of the two volumes and
// the quadrangles of the four named surfaces (the z faces are found by the scene's planes).

R = 10;      // cylinder radius
T = 1;       // thickness in z (one element; the scene makes it plane strain)
W = 20;      // block half-width
H = 20;      // block height
w = 4;       // half-width of the block's finely meshed middle
r = 0.45*R;  // half-width of the cylinder's inner rectangle (its height too)

// Refinement factor: every division count below is multiplied by it (run/gmsh/make_examples
// sets it with -setnumber f N; 1 gives the checked-in mesh).
DefineConstant[ f = 1 ];

nb = 24*f;   // elements along the cylinder's bottom arc (90 degrees) and inner rectangle
ns = 6*f;    // elements along each 45-degree side arc and the rectangle's sides
nr = 6*f;    // elements from the inner rectangle out to the arc
nm = 21*f + 1 - f%2; // elements across the block's middle; odd, so that the cylinder's
             // lowest node meets the middle of a block face, not an edge between two
nw = 8*f;    // elements across each side part of the block
nv = 10*f;   // elements through the block's height

// Cylinder: centre (0, R), the flat side y = R on top.
c = R*Sqrt(0.5);
Point(1) = {0, R, 0};          // centre (arc centre only)
Point(2) = {-R, R, 0};
Point(3) = {R, R, 0};
Point(4) = {-c, R - c, 0};     // 225 degrees
Point(5) = {c, R - c, 0};      // 315 degrees
Point(6) = {-r, R, 0};
Point(7) = {r, R, 0};
Point(8) = {r, R - r, 0};
Point(9) = {-r, R - r, 0};

Circle(1) = {2, 1, 4};         // left side arc
Circle(2) = {4, 1, 5};         // bottom arc (the contact side)
Circle(3) = {5, 1, 3};         // right side arc
Line(4) = {6, 2};              // top, left part (inner to outer)
Line(5) = {6, 7};              // top, middle
Line(6) = {7, 3};              // top, right part (inner to outer)
Line(7) = {9, 4};              // radial, lower left
Line(8) = {8, 5};              // radial, lower right
Line(9) = {9, 8};              // inner rectangle, bottom
Line(10) = {6, 9};             // inner rectangle, left
Line(11) = {7, 8};             // inner rectangle, right

Curve Loop(1) = {5, 11, -9, -10};    // inner rectangle
Curve Loop(2) = {9, 8, -2, -7};      // bottom part
Curve Loop(3) = {-4, 10, 7, -1};     // left part
Curve Loop(4) = {6, -3, -8, -11};    // right part
Plane Surface(1) = {1};
Plane Surface(2) = {2};
Plane Surface(3) = {3};
Plane Surface(4) = {4};

Transfinite Curve {2, 9} = nb + 1 Using Bump 10;
Transfinite Curve {5} = nb + 1;
Transfinite Curve {1, 3, 10, 11} = ns + 1;
Transfinite Curve {4, 6, 7, 8} = nr + 1 Using Progression 0.8;

// Block: top y = 0, three parts side by side, finest at the top middle.
Point(11) = {-W, 0, 0};
Point(12) = {-w, 0, 0};
Point(13) = {w, 0, 0};
Point(14) = {W, 0, 0};
Point(15) = {-W, -H, 0};
Point(16) = {-w, -H, 0};
Point(17) = {w, -H, 0};
Point(18) = {W, -H, 0};
Line(21) = {12, 11};           // top, left part (middle outwards)
Line(22) = {12, 13};           // top, middle
Line(23) = {13, 14};           // top, right part (middle outwards)
Line(24) = {16, 15};           // bottom, left part
Line(25) = {16, 17};           // bottom, middle
Line(26) = {17, 18};           // bottom, right part
Line(27) = {11, 15};           // sides, top downwards
Line(28) = {12, 16};
Line(29) = {13, 17};
Line(30) = {14, 18};

Curve Loop(11) = {-21, 28, 24, -27};
Curve Loop(12) = {22, 29, -25, -28};
Curve Loop(13) = {23, 30, -26, -29};
Plane Surface(11) = {11};
Plane Surface(12) = {12};
Plane Surface(13) = {13};

Transfinite Curve {22, 25} = nm + 1;
Transfinite Curve {21, 23, 24, 26} = nw + 1 Using Progression 1.45;
Transfinite Curve {27, 28, 29, 30} = nv + 1 Using Progression 1.34;

Transfinite Surface {1, 2, 3, 4, 11, 12, 13};
Recombine Surface {1, 2, 3, 4, 11, 12, 13};

// One layer of hexahedra through the thickness. Each extrusion returns
// [top surface, volume, side surfaces in the order of the base surface's curves].
cyl1[] = Extrude {0, 0, T} { Surface{1}; Layers{1}; Recombine; };
cyl2[] = Extrude {0, 0, T} { Surface{2}; Layers{1}; Recombine; };
cyl3[] = Extrude {0, 0, T} { Surface{3}; Layers{1}; Recombine; };
cyl4[] = Extrude {0, 0, T} { Surface{4}; Layers{1}; Recombine; };
blk1[] = Extrude {0, 0, T} { Surface{11}; Layers{1}; Recombine; };
blk2[] = Extrude {0, 0, T} { Surface{12}; Layers{1}; Recombine; };
blk3[] = Extrude {0, 0, T} { Surface{13}; Layers{1}; Recombine; };

Physical Volume("cylinder") = {cyl1[1], cyl2[1], cyl3[1], cyl4[1]};
Physical Volume("block") = {blk1[1], blk2[1], blk3[1]};
// Side surfaces: loop 1 = {5, 11, 9, 10}, loop 2 = {9, 8, 2, 7}, loop 3 = {4, 10, 7, 1},
// loop 4 = {6, 3, 8, 11}; loops 11-13 start with the top curve and end with a side.
Physical Surface("cylinder_top") = {cyl1[2], cyl3[2], cyl4[2]};
Physical Surface("cylinder_arc") = {cyl2[4], cyl3[5], cyl4[3]};
Physical Surface("block_top") = {blk1[2], blk2[2], blk3[2]};
Physical Surface("block_bottom") = {blk1[4], blk2[4], blk3[4]};
