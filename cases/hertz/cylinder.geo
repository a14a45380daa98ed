// Hertz line contact, half model: the quarter disk of a cylinder of radius 1 (centre (0, 1),
// cut on its symmetry line x = 0 and on its horizontal diameter y = 1, where the load acts)
// resting at (0, 0) on a rigid flat (a block whose top is held fixed). Element size
// mesh.size away from the contact (capped by coapt), 0.008 within 0.07 of the contact point,
// both halved per mesh.level.
R = 1;
hc = 0.008;
Point(1) = {0, 0, 0, 1e9};
Point(2) = {0, R, 0, 1e9};
Point(3) = {R, R, 0, 1e9};
Circle(1) = {1, 2, 3};
Line(2) = {3, 2};
Line(3) = {2, 1};
Curve Loop(1) = {1, 2, 3};
Plane Surface(1) = {1};
Point(11) = {-0.1, -0.2, 0, 1e9};
Point(12) = {1.2, -0.2, 0, 1e9};
Point(13) = {1.2, 0, 0, 1e9};
Point(14) = {0, 0, 0, 1e9};
Point(15) = {-0.1, 0, 0, 1e9};
Line(11) = {11, 12};
Line(12) = {12, 13};
Line(13) = {13, 14};
Line(14) = {14, 15};
Line(15) = {15, 11};
Curve Loop(2) = {11, 12, 13, 14, 15};
Plane Surface(2) = {2};
Field[1] = Distance;
Field[1].PointsList = {1};
Field[2] = Threshold;
Field[2].InField = 1;
Field[2].SizeMin = hc;
Field[2].SizeMax = 1e9;
Field[2].DistMin = 0.07;
Field[2].DistMax = 0.07 + 20 * hc;
Background Field = 2;
Physical Curve("cylinder_surface") = {1};
Physical Curve("load") = {2};
Physical Curve("symmetry") = {3};
Physical Curve("plane") = {13, 14};
Physical Curve("flat_sides") = {12, 15};
Physical Curve("foundation") = {11};
Physical Surface("cylinder") = {1};
Physical Surface("flat") = {2};
