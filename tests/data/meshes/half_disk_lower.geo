// The lower half of cases/dfg/disk.geo (the DFG cylinder, radius 0.05 centred at (0.2, 0.2)),
// cut along y = 0.2: its two quarter arcs are the disc's own curves, so the two halves
// together have the disc's boundary nodes (tests/cli/test_fsci_immersed.py: two solids that
// share fluid nodes). Physical groups: boundary, solid.
lc = 1.0;
r = 0.05;
xc = 0.2;
yc = 0.2;

Point(1) = {xc, yc, 0, lc};
Point(2) = {xc + r, yc, 0, lc};
Point(3) = {xc, yc - r, 0, lc};
Point(4) = {xc - r, yc, 0, lc};

Circle(1) = {4, 1, 3};
Circle(2) = {3, 1, 2};
Line(3) = {2, 1};
Line(4) = {1, 4};

Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};

Physical Curve("boundary") = {1, 2, 3, 4};
Physical Surface("solid") = {1};
