// The two leaflets of the 2D valve (valve2d.yaml, contact/leaflets2d.yaml), one mesh with two
// bodies that share no nodes, made in their closed position, as bioprosthetic leaflets are
// fixed: each leaflet is a strip of thickness t whose axis leaves its wall at x = xa at the
// angle theta downstream, bends (axis radius rb) until it runs parallel to the centre line, and
// ends in a straight coaptation segment with a square end. The coaptation faces of the two
// leaflets are parallel, a gap g apart at rest, so the closing valve meets face on face rather
// than tip on tip. The upper leaflet's segment is longer by dl, so that its face covers the end
// of the lower one's (the slave) instead of two corners meeting. The base is embedded a length
// e in the wall (outside the fluid) and clamped there. The upper leaflet otherwise mirrors the
// lower one about y = H/2. Groups: lower, upper (cells); lower_base, upper_base (the clamped
// ends); lower_inner, upper_inner (the sides that face each other: upstream side, bend and
// coaptation face; the contact surfaces); lower_outer, upper_outer (the downstream sides);
// lower_surface, upper_surface (every face but the base). Size lc (halved per mesh.level).
t = 0.0008;       // thickness [m]
g = 0.0001;       // gap between the coaptation faces at rest [m]
lt = 0.0015;      // coaptation length of the lower leaflet [m]
dl = 0.0004;      // the upper leaflet's is longer by dl, so its face covers the lower one's end [m]
rb = 0.0015;      // radius of the bend (axis) [m]
e = 0.001;        // embedded length [m]
xa = 0.012;       // where the axis leaves the wall [m]
H = 0.01;
theta = 60 * Pi / 180;
lc = 0.0002;
c = Cos(theta);
s = Sin(theta);
h = t / 2;
yt = H / 2 - g / 2 - h;            // the coaptation segment's axis
yb = yt - rb * (1 - c);            // where the bend starts
lb = yb / s;                       // belly length from the wall
xb = xa + lb * c;
xc = xb + rb * s;                  // bend centre (xc, yt - rb)
xe = xc + lt;                      // the square end
// lower leaflet: upstream side (left of the axis) and downstream side (right of it)
Point(1) = {xa - e * c + h * s, -e * s - h * c, 0, lc};   // base, downstream side
Point(2) = {xb + h * s, yb - h * c, 0, lc};               // bend start, downstream side
Point(3) = {xc, yt - rb, 0, lc};                          // bend centre
Point(4) = {xc, yt - h, 0, lc};                           // bend end, downstream side
Point(5) = {xe, yt - h, 0, lc};                           // end, downstream corner
Point(6) = {xe, yt + h, 0, lc};                           // end, coaptation corner
Point(7) = {xc, yt + h, 0, lc};                           // bend end, coaptation side
Point(8) = {xb - h * s, yb + h * c, 0, lc};               // bend start, upstream side
Point(9) = {xa - e * c - h * s, -e * s + h * c, 0, lc};   // base, upstream side
Line(1) = {9, 1};
Line(2) = {1, 2};
Circle(3) = {2, 3, 4};
Line(4) = {4, 5};
Line(5) = {5, 6};
Line(6) = {6, 7};
Circle(7) = {7, 3, 8};
Line(8) = {8, 9};
Curve Loop(1) = {1, 2, 3, 4, 5, 6, 7, 8};
Plane Surface(1) = {1};
// upper leaflet: the mirror image y -> H - y
Point(11) = {xa - e * c + h * s, H + e * s + h * c, 0, lc};
Point(12) = {xb + h * s, H - yb + h * c, 0, lc};
Point(13) = {xc, H - yt + rb, 0, lc};
Point(14) = {xc, H - yt + h, 0, lc};
Point(15) = {xe + dl, H - yt + h, 0, lc};
Point(16) = {xe + dl, H - yt - h, 0, lc};
Point(17) = {xc, H - yt - h, 0, lc};
Point(18) = {xb - h * s, H - yb - h * c, 0, lc};
Point(19) = {xa - e * c - h * s, H + e * s - h * c, 0, lc};
Line(11) = {11, 19};
Line(12) = {19, 18};
Circle(13) = {18, 13, 17};
Line(14) = {17, 16};
Line(15) = {16, 15};
Line(16) = {15, 14};
Circle(17) = {14, 13, 12};
Line(18) = {12, 11};
Curve Loop(2) = {11, 12, 13, 14, 15, 16, 17, 18};
Plane Surface(2) = {2};
Physical Curve("lower_base") = {1};
Physical Curve("lower_surface") = {2, 3, 4, 5, 6, 7, 8};
Physical Curve("lower_inner") = {6, 7, 8};
Physical Curve("lower_outer") = {2, 3, 4};
Physical Curve("upper_base") = {11};
Physical Curve("upper_surface") = {12, 13, 14, 15, 16, 17, 18};
Physical Curve("upper_inner") = {12, 13, 14};
Physical Curve("upper_outer") = {16, 17, 18};
Physical Surface("lower") = {1};
Physical Surface("upper") = {2};
