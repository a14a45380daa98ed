// Two stacked boxes for the 3D contact patch test: lower [0,1]^2 x [-0.5, 0], upper
// [0,1]^2 x [0, 0.5], meshed independently (no shared nodes): the lower one at mesh.size, the
// upper one at 0.7 of it, so the interface z = 0 is non-matching at every level.
SetFactory("OpenCASCADE");
Box(1) = {0, 0, -0.5, 1, 1, 0.5};
Box(2) = {0, 0, 0, 1, 1, 0.5};
MeshSize{PointsOf{Volume{1};}} = 1e9;
MeshSize{PointsOf{Volume{2};}} = 0.14;
e = 1e-6;
Physical Surface("base") = Surface In BoundingBox{-e, -e, -0.5 - e, 1 + e, 1 + e, -0.5 + e};
// OpenCASCADE numbers a box's faces x-min, x-max, y-min, y-max, z-min, z-max: the two
// faces at z = 0 are 6 (lower box) and 11 (upper box).
Physical Surface("lower_top") = {6};
Physical Surface("lower_x0") = Surface In BoundingBox{-e, -e, -0.5 - e, e, 1 + e, e};
Physical Surface("lower_y0") = Surface In BoundingBox{-e, -e, -0.5 - e, 1 + e, e, e};
Physical Surface("upper_bottom") = {11};
Physical Surface("upper_x0") = Surface In BoundingBox{-e, -e, -e, e, 1 + e, 0.5 + e};
Physical Surface("upper_y0") = Surface In BoundingBox{-e, -e, -e, 1 + e, e, 0.5 + e};
Physical Surface("upper_top") = Surface In BoundingBox{-e, -e, 0.5 - e, 1 + e, 1 + e, 0.5 + e};
Physical Volume("lower") = {1};
Physical Volume("upper") = {2};
