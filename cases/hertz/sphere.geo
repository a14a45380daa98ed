// Hertz point contact, quarter model: the part x >= 0, y >= 0 of the lower half of a sphere of
// radius 1 (centre (0, 0, 1)), loaded on its flat top z = 1, resting at the origin on a rigid
// flat (a box whose top z = 0 is held fixed).
//
// Element size in the sphere: hc = 0.0125 (a/8 for the contact radius a = 0.1) within the
// distance r0 = 0.12 of the contact point, growing by k = 0.3 per unit distance beyond it
// (a smooth grading: the contact's compliance comes from a zone several a wide), capped at
// mesh.size; all of it halved per mesh.level. The flat is held, so its mesh only carries the
// master surface and stays at mesh.size.
// The sphere is built with its poles on the y axis, so that no pole of the surface's
// parametrisation (where Gmsh's surface mesh degenerates) lies in the contact zone.
SetFactory("OpenCASCADE");
R = 1;
hc = 0.0125;
r0 = 0.12;
k = 0.3;
Sphere(1) = {0, 0, 0, R};
Rotate{{1, 0, 0}, {0, 0, 0}, Pi/2} { Volume{1}; }
Translate{0, 0, R} { Volume{1}; }
Box(2) = {0, 0, 0, R, R, R};
quarter() = BooleanIntersection{ Volume{1}; Delete; }{ Volume{2}; Delete; };
sphere = quarter(0);
Box(3) = {-0.1, -0.1, -0.2, 1.3, 1.3, 0.2};
flat = 3;
MeshSize{PointsOf{Volume{sphere, flat};}} = 1e9;
Field[1] = MathEval;
Field[1].F = Sprintf("%g + %g * Max(0, Sqrt(x^2 + y^2 + z^2) - %g)", hc, k, r0);
// Only in the sphere and on its boundary (older Gmsh: the boundary entities are listed).
faces() = Boundary{ Volume{sphere}; };
edges() = Unique(Abs(Boundary{ Surface{faces()}; }));
Field[2] = Restrict;
Field[2].IField = 1;
Field[2].VolumesList = {sphere};
Field[2].FacesList = {faces()};
Field[2].EdgesList = {edges()};
Background Field = 2;
e = 1e-6;
Physical Surface("load") = Surface In BoundingBox{-e, -e, R - e, R + e, R + e, R + e};
Physical Surface("symmetry_x") = Surface In BoundingBox{-e, -e, -e, e, R + e, R + e};
Physical Surface("symmetry_y") = Surface In BoundingBox{-e, -e, -e, R + e, e, R + e};
// The spherical face: every face of the sphere volume that is not one of the three above.
curved() = faces();
curved() -= Surface In BoundingBox{-e, -e, R - e, R + e, R + e, R + e};
curved() -= Surface In BoundingBox{-e, -e, -e, e, R + e, R + e};
curved() -= Surface In BoundingBox{-e, -e, -e, R + e, e, R + e};
Physical Surface("sphere_surface") = curved();
Physical Surface("plane") = Surface In BoundingBox{-0.1 - e, -0.1 - e, -e, 1.2 + e, 1.2 + e, e};
Physical Surface("foundation") = Surface In BoundingBox{-0.1 - e, -0.1 - e, -0.2 - e, 1.2 + e, 1.2 + e, -0.2 + e};
Physical Volume("sphere") = {sphere};
Physical Volume("flat") = {flat};
