// The ball in a box of method/paper.md §3.1 (after Laursen and Love 2002), plane strain:
// a disc of diameter 20 centred at (140, 50) inside the square box [0, 200]^2, whose wall is
// the frame between it and [-10, 210]^2. The two bodies share no nodes. Sizes: 2 on the disc
// and 5 on the inner wall at level 0 (the frame's outer corners take mesh.size), every size
// halved per level.
r = 10;
xc = 140;
yc = 50;
h_ball = 2;
h_wall = 5;
// ball
Point(1) = {xc, yc, 0, h_ball};
Point(2) = {xc + r, yc, 0, h_ball};
Point(3) = {xc, yc + r, 0, h_ball};
Point(4) = {xc - r, yc, 0, h_ball};
Point(5) = {xc, yc - r, 0, h_ball};
Circle(1) = {2, 1, 3};
Circle(2) = {3, 1, 4};
Circle(3) = {4, 1, 5};
Circle(4) = {5, 1, 2};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
// box: inner square and outer square
Point(11) = {0, 0, 0, h_wall};
Point(12) = {200, 0, 0, h_wall};
Point(13) = {200, 200, 0, h_wall};
Point(14) = {0, 200, 0, h_wall};
Point(15) = {-10, -10, 0, 1e9};
Point(16) = {210, -10, 0, 1e9};
Point(17) = {210, 210, 0, 1e9};
Point(18) = {-10, 210, 0, 1e9};
Line(11) = {11, 12};
Line(12) = {12, 13};
Line(13) = {13, 14};
Line(14) = {14, 11};
Line(15) = {15, 16};
Line(16) = {16, 17};
Line(17) = {17, 18};
Line(18) = {18, 15};
Curve Loop(2) = {15, 16, 17, 18};
Curve Loop(3) = {11, 12, 13, 14};
Plane Surface(2) = {2, 3};
Physical Curve("ball_surface") = {1, 2, 3, 4};
Physical Curve("box_inner") = {11, 12, 13, 14};
Physical Curve("box_outer") = {15, 16, 17, 18};
Physical Surface("ball") = {1};
Physical Surface("box") = {2};
