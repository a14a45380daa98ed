// Turek-Hron FSI channel [0, 2.5] x [0, 0.41] with the rigid cylinder (centre (0.2, 0.2),
// r = 0.05) as a hole; the elastic bar is NOT cut out: the fluid mesh overlaps it (immersed,
// fsi1.yaml). Physical groups: inlet (x = 0), outlet (x = 2.5), walls (y = 0 and y = 0.41),
// cylinder, fluid. Sizes: lc_body on the cylinder, lc_bar in a box around the bar and its
// range of motion (a Box field with a transition layer), lc_far (capped by the case's
// mesh.size through Mesh.MeshSizeMax) elsewhere. Each mesh.level halves every size.
lc_far = 1.0;
lc_body = 0.005;
lc_bar = 0.0025;
r = 0.05;
xc = 0.2;
yc = 0.2;

Point(1) = {0, 0, 0, lc_far};
Point(2) = {2.5, 0, 0, lc_far};
Point(3) = {2.5, 0.41, 0, lc_far};
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

Field[1] = Box;
Field[1].VIn = lc_bar;
Field[1].VOut = lc_far;
Field[1].XMin = 0.23;
Field[1].XMax = 0.63;
Field[1].YMin = 0.17;
Field[1].YMax = 0.23;
Field[1].Thickness = 0.1;
Background Field = 1;

Physical Curve("inlet") = {4};
Physical Curve("outlet") = {2};
Physical Curve("walls") = {1, 3};
Physical Curve("cylinder") = {5, 6, 7, 8};
Physical Surface("fluid") = {1};
