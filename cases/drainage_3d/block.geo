// A block of coal 4 m deep (x), 2 m high (y) and 3 m wide (z) behind a face
// at x = 0, its first metre softened: hexahedra of 0.5 m, from two
// transfinite, recombined rectangles extruded in layers along z. The tests
// read it (tests/test_seepage_3d_scenes.cpp); regenerate it with
//   gmsh -3 -format msh41 block.geo -o block.msh
Point(1) = {0, 0, 0};
Point(2) = {1, 0, 0};
Point(3) = {4, 0, 0};
Point(4) = {4, 2, 0};
Point(5) = {1, 2, 0};
Point(6) = {0, 2, 0};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 5};
Line(5) = {5, 6};
Line(6) = {6, 1};
Line(7) = {2, 5};
Curve Loop(1) = {1, 7, 5, 6};
Plane Surface(1) = {1};
Curve Loop(2) = {2, 3, 4, -7};
Plane Surface(2) = {2};
// Node counts per curve: 0.5 m cells throughout.
Transfinite Curve{1, 5} = 3;
Transfinite Curve{2, 4} = 7;
Transfinite Curve{3, 6, 7} = 5;
Transfinite Surface{1, 2};
Recombine Surface{1, 2};
// Each extrusion lists the top, the volume, then the sides grown from the
// rectangle's curves in its loop's order.
softened[] = Extrude {0, 0, 3} { Surface{1}; Layers{6}; Recombine; };
coal[] = Extrude {0, 0, 3} { Surface{2}; Layers{6}; Recombine; };

Physical Volume("softened") = {softened[1]};
Physical Volume("coal") = {coal[1]};
Physical Surface("face") = {softened[5]};
Physical Surface("far_end") = {coal[3]};
Physical Surface("floor") = {softened[2], coal[2]};
Physical Surface("roof") = {softened[4], coal[4]};
Physical Surface("back") = {1, 2};
Physical Surface("front") = {softened[0], coal[0]};
