// Gas seepage domain of the outburst case: the coal seam (20 m deep, 9 m high,
// right) and the tunnel in front of its face (3 m high, 25 m long unless
// `tunnel` is set, left, between the roof and floor rock, which carry no gas).
// Structured quadrilaterals of h = 0.5 m so that the face and the tunnel walls
// lie on element edges (sensitivity.py meshes h = 0.25 m too).
// Regenerate: gmsh -2 -format msh41 seam.geo -o seam.msh
// and the 100 m tunnel of the run to rest (README.md):
// gmsh -2 -format msh41 -setnumber tunnel 100 seam.geo -o seam_long.msh
// (committed meshes made with Gmsh 4.8.4, Debian 12's package)
DefineConstant[ h = 0.5 ];  // element edge [m]
DefineConstant[ tunnel = 25 ];  // tunnel length [m]; the face stays at x = 25 m
Point(1) = {25, 0, 0};  Point(2) = {45, 0, 0};  Point(3) = {45, 3, 0};  Point(4) = {45, 6, 0};
Point(5) = {45, 9, 0};  Point(6) = {25, 9, 0};  Point(7) = {25, 6, 0};  Point(8) = {25, 3, 0};
Point(9) = {25 - tunnel, 3, 0};   Point(10) = {25 - tunnel, 6, 0};
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
Transfinite Curve{11, 12} = tunnel / h + 1;
Transfinite Surface{1, 2, 3, 4};
Recombine Surface{1, 2, 3, 4};
Physical Surface("coal") = {1, 2, 3};
Physical Surface("tunnel") = {4};
Physical Curve("tunnel_end") = {13};
