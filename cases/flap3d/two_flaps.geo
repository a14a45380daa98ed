// The two flaps of cases/flap3d/contact.yaml, one mesh with two bodies that share no nodes, in
// metres: the front flap [0.3, 0.34] x [0.1, 0.3] x [0, 0.2] (flap3d.yaml's flap) and the back
// flap [0.345, 0.385] x [0.1, 0.3] x [0, 0.2], 5 mm behind it, both standing on the channel's
// floor z = 0. Size lc (capped by the case's mesh.size, halved per mesh.level). Groups: front,
// back (cells); front_bottom, back_bottom (z = 0: clamped); front_downstream (the front flap's
// face x = 0.34), back_upstream (the back flap's face x = 0.345): the faces that meet.
SetFactory("OpenCASCADE");
lc = 1.0;
Box(1) = {0.3, 0.1, 0.0, 0.04, 0.2, 0.2};
Box(2) = {0.34, 0.1, 0.0, 0.04, 0.2, 0.2};
MeshSize{PointsOf{Volume{1, 2};}} = lc;
// OpenCASCADE numbers a box's faces x-min, x-max, y-min, y-max, z-min, z-max: box 1 has
// faces 1-6, box 2 faces 7-12.
Physical Surface("front_bottom") = {5};
Physical Surface("front_downstream") = {2};
Physical Surface("back_bottom") = {11};
Physical Surface("back_upstream") = {7};
Physical Volume("front") = {1};
Physical Volume("back") = {2};
