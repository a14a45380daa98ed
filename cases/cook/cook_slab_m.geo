// Cook's membrane as a slab in metres: the trapezoid (0,0), (48,44), (48,60), (0,44) mm in the
// plane z = 0, extruded by 0.5 mm along z: the half (z >= 0) of a 1 mm thick slab whose two
// faces z = -0.5 mm and z = 0.5 mm are free, cut at its mid-plane (neohookean.yaml fixes u_z
// there, the symmetry condition). Meshed by coapt at the case's mesh.size (Mesh.MeshSizeMax),
// halved per mesh.level. Groups: left (clamped), right (loaded), bottom, top, mid_plane
// (z = 0), face (z = 0.5 mm); cells: domain.
Point(1) = {0, 0, 0};
Point(2) = {0.048, 0.044, 0};
Point(3) = {0.048, 0.060, 0};
Point(4) = {0, 0.044, 0};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
slab[] = Extrude {0, 0, 0.0005} { Surface{1}; };
// slab[0]: the face z = 0.5 mm, slab[1]: the volume, slab[2..5]: the sides swept by lines 1..4
Physical Surface("mid_plane") = {1};
Physical Surface("face") = {slab[0]};
Physical Surface("bottom") = {slab[2]};
Physical Surface("right") = {slab[3]};
Physical Surface("top") = {slab[4]};
Physical Surface("left") = {slab[5]};
Physical Volume("domain") = {slab[1]};
