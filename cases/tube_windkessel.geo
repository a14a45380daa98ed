// Straight tube for the Windkessel outlet case: radius 0.01 m, length 0.1 m along x, inlet at
// x = 0, outlet at x = 0.1. Physical groups: inlet, outlet, wall (the lateral surface), fluid.
// The point size is large on purpose: the case's mesh.size caps it (Mesh.MeshSizeMax).
lc = 1.0;
r = 0.01;
length = 0.1;

Point(1) = {0, 0, 0, lc};
Point(2) = {0, r, 0, lc};
Point(3) = {0, 0, r, lc};
Point(4) = {0, -r, 0, lc};
Point(5) = {0, 0, -r, lc};
Circle(1) = {2, 1, 3};
Circle(2) = {3, 1, 4};
Circle(3) = {4, 1, 5};
Circle(4) = {5, 1, 2};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
tube[] = Extrude {length, 0, 0} { Surface{1}; };

Physical Surface("inlet") = {1};
Physical Surface("outlet") = {tube[0]};
Physical Surface("wall") = {tube[2], tube[3], tube[4], tube[5]};
Physical Volume("fluid") = {tube[1]};
