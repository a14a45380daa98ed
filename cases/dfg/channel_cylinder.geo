// Schäfer-Turek (DFG 1996) 2D channel: [0, 2.2] x [0, 0.41] without the disc of radius 0.05
// centred at (0.2, 0.2). Physical groups: inlet (x = 0), outlet (x = 2.2), walls (y = 0 and
// y = 0.41), cylinder, fluid. The point sizes refine the mesh near the cylinder: lc_body there,
// lc_far (which the case's mesh.size caps through Mesh.MeshSizeMax) on the channel corners;
// Gmsh grades the size in between. Each mesh.level halves every size (Mesh.MeshSizeFactor),
// the cylinder's included.
lc_far = 1.0;
lc_body = 0.005;
r = 0.05;
xc = 0.2;
yc = 0.2;

Point(1) = {0, 0, 0, lc_far};
Point(2) = {2.2, 0, 0, lc_far};
Point(3) = {2.2, 0.41, 0, lc_far};
Point(4) = {0, 0.41, 0, lc_far};
Point(5) = {xc, yc, 0, lc_body};
Point(6) = {xc + r, yc, 0, lc_body};
Point(7) = {xc, yc + r, 0, lc_body};
Point(8) = {xc - r, yc, 0, lc_body};
Point(9) = {xc, yc - r, 0, lc_body};

Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Circle(5) = {6, 5, 7};
Circle(6) = {7, 5, 8};
Circle(7) = {8, 5, 9};
Circle(8) = {9, 5, 6};

Curve Loop(1) = {1, 2, 3, 4};
Curve Loop(2) = {5, 6, 7, 8};
Plane Surface(1) = {1, 2};

Physical Curve("inlet") = {4};
Physical Curve("outlet") = {2};
Physical Curve("walls") = {1, 3};
Physical Curve("cylinder") = {5, 6, 7, 8};
Physical Surface("fluid") = {1};
