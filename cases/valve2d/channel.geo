// The fluid of the 2D valve (valve2d.yaml): the channel [0, 0.04] x [0, 0.01] m, meshed
// through the leaflets (immersed: the fluid mesh fills their region). Groups: inlet (x = 0),
// outlet (x = 0.04), walls (y = 0 and y = 0.01), fluid. Sizes: lc_valve in the box
// 0.0085 <= x <= 0.0215 around the leaflets and their range of motion (a Box field with a
// transition layer), lc_far (capped by the case's mesh.size) elsewhere; each mesh.level halves
// every size.
lc_far = 1.0;
lc_valve = 0.00025;
L = 0.04;
H = 0.01;
Point(1) = {0, 0, 0, lc_far};
Point(2) = {L, 0, 0, lc_far};
Point(3) = {L, H, 0, lc_far};
Point(4) = {0, H, 0, lc_far};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Field[1] = Box;
Field[1].VIn = lc_valve;
Field[1].VOut = lc_far;
Field[1].XMin = 0.0085;
Field[1].XMax = 0.0215;
Field[1].YMin = -0.001;
Field[1].YMax = H + 0.001;
Field[1].Thickness = 0.004;
Background Field = 1;
Physical Curve("inlet") = {4};
Physical Curve("outlet") = {2};
Physical Curve("walls") = {1, 3};
Physical Surface("fluid") = {1};
