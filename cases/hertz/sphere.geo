// Hertz point contact, quarter model: the part x >= 0, y >= 0 of the lower half of a sphere of
// radius 1 (centre (0, 0, 1)), loaded on its flat top z = 1, resting at the origin on a rigid
// flat (a box whose top z = 0 is held fixed). Element size mesh.size away from the contact
// (capped by coapt), 0.025 within the box |x|, |y| < 0.15, z < 0.05 around the contact point,
// both halved per mesh.level.
SetFactory("OpenCASCADE");
R = 1;
hc = 0.025;
Sphere(1) = {0, 0, R, R, -Pi/2, 0, Pi/2};
Box(2) = {-0.1, -0.1, -0.2, 1.3, 1.3, 0.2};
MeshSize{PointsOf{Volume{1, 2};}} = 1e9;
Field[1] = Box;
Field[1].VIn = hc;
Field[1].VOut = 1e9;
Field[1].XMin = -0.2;
Field[1].XMax = 0.15;
Field[1].YMin = -0.2;
Field[1].YMax = 0.15;
Field[1].ZMin = -0.05;
Field[1].ZMax = 0.05;
Field[1].Thickness = 0.3;
Background Field = 1;
e = 1e-6;
Physical Surface("load") = Surface In BoundingBox{-e, -e, R - e, R + e, R + e, R + e};
Physical Surface("symmetry_x") = Surface In BoundingBox{-e, -e, -e, e, R + e, R + e};
Physical Surface("symmetry_y") = Surface In BoundingBox{-e, -e, -e, R + e, e, R + e};
// The spherical face: every face of the sphere volume that is not one of the three above.
sphere() = Boundary{Volume{1};};
plane() = Surface In BoundingBox{-e, -e, R - e, R + e, R + e, R + e};
plane() += Surface In BoundingBox{-e, -e, -e, e, R + e, R + e};
plane() += Surface In BoundingBox{-e, -e, -e, R + e, e, R + e};
sphere() -= plane();
Physical Surface("sphere_surface") = sphere();
Physical Surface("plane") = Surface In BoundingBox{-0.1 - e, -0.1 - e, -e, 1.2 + e, 1.2 + e, e};
Physical Surface("foundation") = Surface In BoundingBox{-0.1 - e, -0.1 - e, -0.2 - e, 1.2 + e, 1.2 + e, -0.2 + e};
Physical Volume("sphere") = {1};
Physical Volume("flat") = {2};
