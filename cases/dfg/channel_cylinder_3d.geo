// Schäfer-Turek (DFG 1996) 3D channel with a circular cylinder: [0, 2.5] x [0, 0.41] x [0, 0.41]
// without the cylinder of diameter 0.1 whose axis is parallel to z through (0.5, 0.2) (it spans
// the channel's height). Physical groups: inlet (x = 0), outlet (x = 2.5), walls (y = 0, 0.41
// and z = 0, 0.41), cylinder, fluid. Built as the 2D cross-section (as in channel_cylinder.geo)
// extruded along z; lc_body refines the mesh at the cylinder, lc_far (capped by the case's
// mesh.size through Mesh.MeshSizeMax) at the channel corners, and each mesh.level halves every
// size (Mesh.MeshSizeFactor).
lc_far = 1.0;
lc_body = 0.01;
r = 0.05;
xc = 0.5;
yc = 0.2;
h = 0.41;

Point(1) = {0, 0, 0, lc_far};
Point(2) = {2.5, 0, 0, lc_far};
Point(3) = {2.5, h, 0, lc_far};
Point(4) = {0, h, 0, lc_far};
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

// out[0]: the top (z = h), out[1]: the volume, out[2..5]: the sides swept by lines 1-4,
// out[6..9]: the cylinder quarters swept by circles 5-8.
out[] = Extrude {0, 0, h} { Surface{1}; };

Physical Surface("inlet") = {out[5]};
Physical Surface("outlet") = {out[3]};
Physical Surface("walls") = {1, out[0], out[2], out[4]};
Physical Surface("cylinder") = {out[6], out[7], out[8], out[9]};
Physical Volume("fluid") = {out[1]};
