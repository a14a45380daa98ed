// The master of cases/transfer/analytic2d.yaml: the disc of radius 0.4 centred at (0.5, 0.5),
// meshed by Gmsh (unstructured). Physical groups: boundary (the circle), solid (the disc).
// The case's mesh.master.size caps the element size (Mesh.MeshSizeMax); each level halves it.
r = 0.4;
xc = 0.5;
yc = 0.5;
lc = 1.0;

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
