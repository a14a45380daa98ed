// Two stacked blocks for the 2D contact patch test: lower [0, 1] x [-0.5, 0], upper
// [0, 1] x [0, 0.5], meshed independently (no shared nodes) with different sizes, so their
// interface y = 0 is non-matching at every level (lower: mesh.size, upper: 0.07 at level 0,
// both halved per level).
Point(1) = {0, -0.5, 0, 1e9};
Point(2) = {1, -0.5, 0, 1e9};
Point(3) = {1, 0, 0, 1e9};
Point(4) = {0, 0, 0, 1e9};
Point(5) = {0, 0, 0, 0.07};
Point(6) = {1, 0, 0, 0.07};
Point(7) = {1, 0.5, 0, 0.07};
Point(8) = {0, 0.5, 0, 0.07};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Line(5) = {5, 6};
Line(6) = {6, 7};
Line(7) = {7, 8};
Line(8) = {8, 5};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Curve Loop(2) = {5, 6, 7, 8};
Plane Surface(2) = {2};
Physical Curve("base") = {1};
Physical Curve("lower_right") = {2};
Physical Curve("lower_top") = {3};
Physical Curve("lower_left") = {4};
Physical Curve("upper_bottom") = {5};
Physical Curve("upper_right") = {6};
Physical Curve("upper_top") = {7};
Physical Curve("upper_left") = {8};
Physical Surface("lower") = {1};
Physical Surface("upper") = {2};
