// channel_bar.geo with the obstacle's surface in two groups, "cylinder" (the circular arc) and
// "bar" (the bar's three free sides), so that the load on the bar alone can be read (cfd1_split.yaml).
// Turek-Hron channel [0, 2.5] x [0, 0.41] with the rigid obstacle cut out (body-fitted CFD1-3):
// the cylinder (centre (0.2, 0.2), r = 0.05) and the bar [0.2490, 0.6] x [0.19, 0.21] attached to
// its right, whose left corners lie on the circle at x = 0.2 + sqrt(0.05^2 - 0.01^2).
// Physical groups: inlet (x = 0), outlet (x = 2.5), walls (y = 0 and y = 0.41), cylinder (the
// circular arc), bar (the bar's three free sides), fluid. Sizes: lc_body on the cylinder, lc_bar on
// the bar, lc_far (capped by the case's mesh.size through Mesh.MeshSizeMax) at the channel
// corners; Gmsh grades the size in between. Each mesh.level halves every size.
lc_far = 1.0;
lc_body = 0.005;
lc_bar = 0.005;
lc_tip = 0.0025;
r = 0.05;
xc = 0.2;
yc = 0.2;
h = 0.01;                        // half the bar's thickness
xa = xc + Sqrt(r * r - h * h);   // where the bar meets the circle
xt = 0.6;                        // the bar's tip

Point(1) = {0, 0, 0, lc_far};
Point(2) = {2.5, 0, 0, lc_far};
Point(3) = {2.5, 0.41, 0, lc_far};
Point(4) = {0, 0.41, 0, lc_far};
Point(5) = {xc, yc, 0, lc_body};
Point(6) = {xa, yc + h, 0, lc_body};
Point(7) = {xc, yc + r, 0, lc_body};
Point(8) = {xc - r, yc, 0, lc_body};
Point(9) = {xc, yc - r, 0, lc_body};
Point(10) = {xa, yc - h, 0, lc_body};
Point(11) = {xt, yc - h, 0, lc_tip};
Point(12) = {xt, yc + h, 0, lc_tip};

Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Circle(5) = {6, 5, 7};
Circle(6) = {7, 5, 8};
Circle(7) = {8, 5, 9};
Circle(8) = {9, 5, 10};
Line(9) = {10, 11};
Line(10) = {11, 12};
Line(11) = {12, 6};

Curve Loop(1) = {1, 2, 3, 4};
Curve Loop(2) = {5, 6, 7, 8, 9, 10, 11};
Plane Surface(1) = {1, 2};

// lc_bar along the bar's sides (the point sizes alone would grow it towards the middle).
Field[1] = Box;
Field[1].VIn = lc_bar;
Field[1].VOut = lc_far;
Field[1].XMin = xa;
Field[1].XMax = xt;
Field[1].YMin = yc - h;
Field[1].YMax = yc + h;
Field[1].Thickness = 0.05;
Background Field = 1;

Physical Curve("inlet") = {4};
Physical Curve("outlet") = {2};
Physical Curve("walls") = {1, 3};
Physical Curve("cylinder") = {5, 6, 7, 8};
Physical Curve("bar") = {9, 10, 11};
Physical Surface("fluid") = {1};
