// Two coal layers in series along x, meshed with unstructured quadrangles.
// Regenerate: gmsh -2 -format msh41 two_layers.geo -o two_layers.msh
// (committed mesh made with Gmsh 4.8.4, Debian 12's package)
h = 0.25;
Point(1) = {0, 0, 0, h};
Point(2) = {4, 0, 0, h};
Point(3) = {10, 0, 0, h};
Point(4) = {10, 1, 0, h};
Point(5) = {4, 1, 0, h};
Point(6) = {0, 1, 0, h};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 5};
Line(5) = {5, 6};
Line(6) = {6, 1};
Line(7) = {2, 5};
Curve Loop(1) = {1, 7, 5, 6};
Curve Loop(2) = {2, 3, 4, -7};
Plane Surface(1) = {1};
Plane Surface(2) = {2};
Recombine Surface{1, 2};
Mesh.Algorithm = 6;          // frontal-Delaunay, then recombined
Mesh.RecombinationAlgorithm = 2;
Physical Surface("soft") = {1};
Physical Surface("hard") = {2};
Physical Curve("inlet") = {6};
Physical Curve("outlet") = {3};
Physical Curve("walls") = {1, 2, 4, 5};
