// The two leaflets of the 2D valve (valve2d.yaml), one mesh with two bodies that share no
// nodes. Each leaflet is a strip of thickness t with a rounded tip (a half disc of radius t/2)
// whose axis leaves its wall at x = xa at the angle theta downstream; its base is embedded a
// length e in the wall (outside the fluid) and clamped there. The upper leaflet mirrors the
// lower one about y = H/2. At rest the tips are 2 (H/2 - l sin(theta)) - t apart; turned
// upstream to about 50 degrees they meet on the centre line. Groups: lower, upper (cells),
// lower_base, upper_base (the clamped ends), lower_surface, upper_surface (the rest of each
// boundary: the contact surfaces). Size lc (halved per mesh.level).
t = 0.0008;       // thickness [m]
l = 0.0065;       // length of the axis from the wall to the tip centre [m]
e = 0.001;        // embedded length [m]
xa = 0.012;       // where the axis leaves the wall [m]
H = 0.01;
theta = 35 * Pi / 180;
lc = 0.0002;
c = Cos(theta);
s = Sin(theta);
h = t / 2;
// lower leaflet: axis point O + r d, d = (c, s); side normal m = (-s, c)
Point(1) = {xa - e * c + h * s, -e * s - h * c, 0, lc};   // base, downstream side
Point(2) = {xa + l * c + h * s, l * s - h * c, 0, lc};    // tip, downstream side
Point(3) = {xa + l * c, l * s, 0, lc};                    // tip centre
Point(4) = {xa + (l + h) * c, (l + h) * s, 0, lc};        // tip
Point(5) = {xa + l * c - h * s, l * s + h * c, 0, lc};    // tip, upstream side
Point(6) = {xa - e * c - h * s, -e * s + h * c, 0, lc};   // base, upstream side
Line(1) = {6, 1};
Line(2) = {1, 2};
Circle(3) = {2, 3, 4};
Circle(4) = {4, 3, 5};
Line(5) = {5, 6};
Curve Loop(1) = {1, 2, 3, 4, 5};
Plane Surface(1) = {1};
// upper leaflet: the mirror image y -> H - y
Point(11) = {xa - e * c + h * s, H + e * s + h * c, 0, lc};
Point(12) = {xa + l * c + h * s, H - l * s + h * c, 0, lc};
Point(13) = {xa + l * c, H - l * s, 0, lc};
Point(14) = {xa + (l + h) * c, H - (l + h) * s, 0, lc};
Point(15) = {xa + l * c - h * s, H - l * s - h * c, 0, lc};
Point(16) = {xa - e * c - h * s, H + e * s - h * c, 0, lc};
Line(11) = {11, 16};
Line(12) = {16, 15};
Circle(13) = {15, 13, 14};
Circle(14) = {14, 13, 12};
Line(15) = {12, 11};
Curve Loop(2) = {11, 12, 13, 14, 15};
Plane Surface(2) = {2};
Physical Curve("lower_base") = {1};
Physical Curve("lower_surface") = {2, 3, 4, 5};
Physical Curve("upper_base") = {11};
Physical Curve("upper_surface") = {12, 13, 14, 15};
Physical Surface("lower") = {1};
Physical Surface("upper") = {2};
