// Gas seepage domain of the 3D outburst (outburst_3d.toml): the coal seam
// (x = 25..45 m, y = 0..9 m, z = 0..6 m) and the heading in front of its face
// (x = 0..25 m, y = 3..6 m, z = 0..2 m: half of a heading 4 m wide, z = 0
// its plane of symmetry), between the floor, roof and side rock, which carry
// no gas. The plane case's section (../outburst/seam.geo: three coal strips
// and the tunnel, quadrilaterals of h) grown along z in two layers of
// hexahedra: z = 0..2 m with the tunnel, z = 2..6 m the coal alone; the
// heading's wall at z = 2 m is the side rock's face (no flow).
// Regenerate: gmsh -3 -format msh41 heading.geo -o heading.msh
// (committed mesh made with Gmsh 4.8.4, Debian 12's package)
DefineConstant[ h = 0.5 ];       // element edge [m]
DefineConstant[ half = 2 ];      // the heading's half-width [m]
DefineConstant[ depth = 6 ];     // the seam's extent along z [m]
Point(1) = {25, 0, 0};  Point(2) = {45, 0, 0};  Point(3) = {45, 3, 0};  Point(4) = {45, 6, 0};
Point(5) = {45, 9, 0};  Point(6) = {25, 9, 0};  Point(7) = {25, 6, 0};  Point(8) = {25, 3, 0};
Point(9) = {0, 3, 0};   Point(10) = {0, 6, 0};
Line(1) = {1, 2};  Line(2) = {2, 3};  Line(3) = {3, 4};  Line(4) = {4, 5};
Line(5) = {5, 6};  Line(6) = {6, 7};  Line(7) = {7, 8};  Line(8) = {8, 1};
Line(9) = {8, 3};  Line(10) = {7, 4};                      // coal: lower, middle, upper strips
Line(11) = {9, 8}; Line(12) = {10, 7}; Line(13) = {9, 10};  // tunnel
Curve Loop(1) = {1, 2, -9, 8};    Plane Surface(1) = {1};
Curve Loop(2) = {9, 3, -10, 7};   Plane Surface(2) = {2};
Curve Loop(3) = {10, 4, 5, 6};    Plane Surface(3) = {3};
Curve Loop(4) = {11, -7, -12, -13}; Plane Surface(4) = {4};
Transfinite Curve{1, 9, 10, 5} = 20 / h + 1;
Transfinite Curve{2, 8, 4, 6, 3, 7, 13} = 3 / h + 1;
Transfinite Curve{11, 12} = 25 / h + 1;
Transfinite Surface{1, 2, 3, 4};
Recombine Surface{1, 2, 3, 4};
// Each extrusion lists the top, the volume, then the sides grown from the
// surface's curves in its loop's order.
lower[] = Extrude {0, 0, half} { Surface{1}; Layers{half / h}; Recombine; };
middle[] = Extrude {0, 0, half} { Surface{2}; Layers{half / h}; Recombine; };
upper[] = Extrude {0, 0, half} { Surface{3}; Layers{half / h}; Recombine; };
heading[] = Extrude {0, 0, half} { Surface{4}; Layers{half / h}; Recombine; };
lower2[] = Extrude {0, 0, depth - half} { Surface{lower[0]}; Layers{(depth - half) / h}; Recombine; };
middle2[] = Extrude {0, 0, depth - half} { Surface{middle[0]}; Layers{(depth - half) / h}; Recombine; };
upper2[] = Extrude {0, 0, depth - half} { Surface{upper[0]}; Layers{(depth - half) / h}; Recombine; };
Physical Volume("coal") = {lower[1], middle[1], upper[1], lower2[1], middle2[1], upper2[1]};
Physical Volume("tunnel") = {heading[1]};
// The heading's end: the side grown from curve 13, the fourth of loop 4.
Physical Surface("tunnel_end") = {heading[5]};
