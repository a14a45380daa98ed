// Schäfer-Turek (DFG 1996) 2D channel [0, 2.2] x [0, 0.41] meshed WITHOUT the cylinder: the
// disc of radius 0.05 centred at (0.2, 0.2) is filled with fluid cells that do not follow its
// boundary (the immersed cylinder is a separate solid mesh, disk.geo). Physical groups: inlet
// (x = 0), outlet (x = 2.2), walls (y = 0 and y = 0.41), fluid. A size field refines the mesh
// around the cylinder's position: lc_body + grading r², r the distance to the centre, capped by
// the far-field size (the case's mesh.size through Mesh.MeshSizeMax). Each mesh.level halves
// every size (Mesh.MeshSizeFactor), the field's included.
lc_far = 1.0;
lc_body = 0.005;
grading = 0.5;
xc = 0.2;
yc = 0.2;

Point(1) = {0, 0, 0, lc_far};
Point(2) = {2.2, 0, 0, lc_far};
Point(3) = {2.2, 0.41, 0, lc_far};
Point(4) = {0, 0.41, 0, lc_far};

Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};

Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};

Field[1] = MathEval;
Field[1].F = Sprintf("%g + %g * ((x - %g)^2 + (y - %g)^2)", lc_body, grading, xc, yc);
Background Field = 1;
Mesh.MeshSizeExtendFromBoundary = 0;

Physical Curve("inlet") = {4};
Physical Curve("outlet") = {2};
Physical Curve("walls") = {1, 3};
Physical Surface("fluid") = {1};
