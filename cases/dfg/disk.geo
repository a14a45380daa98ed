// The DFG cylinder as a solid mesh: the disc of radius 0.05 centred at (0.2, 0.2), for the
// immersed 2D-1 case (2d1_immersed.yaml). Physical groups: boundary (the circle), solid.
// Each mesh.level halves the size (the case's mesh.size caps lc).
lc = 1.0;
r = 0.05;
xc = 0.2;
yc = 0.2;

Point(1) = {xc, yc, 0, lc};
Point(2) = {xc + r, yc, 0, lc};
Point(3) = {xc, yc + r, 0, lc};
Point(4) = {xc - r, yc, 0, lc};
Point(5) = {xc, yc - r, 0, lc};

Circle(1) = {2, 1, 3};
Circle(2) = {3, 1, 4};
Circle(3) = {4, 1, 5};
Circle(4) = {5, 1, 2};

Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};

Physical Curve("boundary") = {1, 2, 3, 4};
Physical Surface("solid") = {1};
