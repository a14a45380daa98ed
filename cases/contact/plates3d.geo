// Two thin plates for the sliding contact case (cases/contact/plates3d.yaml), in metres: the
// lower plate [0, 8] x [0, 8] x [-1, 0] mm, the upper one [1.5, 6.5] x [1.5, 6.5] x [0, 1] mm
// resting on it, meshed independently (no shared nodes): the lower one at mesh.size (capped by
// coapt), the upper one at 0.4 mm, both halved per mesh.level, so the interface z = 0 is
// non-matching at every level. At level 0 (mesh.size 0.5 mm) each plate has 2 to 3 elements
// through its 1 mm thickness.
SetFactory("OpenCASCADE");
mm = 1e-3;
Box(1) = {0, 0, -1 * mm, 8 * mm, 8 * mm, 1 * mm};
Box(2) = {1.5 * mm, 1.5 * mm, 0, 5 * mm, 5 * mm, 1 * mm};
MeshSize{PointsOf{Volume{1};}} = 1e9;
MeshSize{PointsOf{Volume{2};}} = 0.4 * mm;
// OpenCASCADE numbers a box's faces x-min, x-max, y-min, y-max, z-min, z-max: box 1 has
// faces 1-6, box 2 faces 7-12.
Physical Surface("lower_bottom") = {5};
Physical Surface("lower_top") = {6};
Physical Surface("upper_bottom") = {11};
Physical Surface("upper_top") = {12};
Physical Volume("lower") = {1};
Physical Volume("upper") = {2};
