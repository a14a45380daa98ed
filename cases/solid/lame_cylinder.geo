// A quarter of a thick-walled cylinder (inner radius 10 mm, outer 20 mm, length 5 mm) in
// metres, for Lame's problem: x >= 0, y >= 0, 0 <= z <= 5 mm.
// Meshed by coapt at the case's mesh.size (Mesh.MeshSizeMax), halved per mesh.level.
a = 0.01;
b = 0.02;
L = 0.005;
Point(1) = {0, 0, 0};
Point(2) = {a, 0, 0};
Point(3) = {b, 0, 0};
Point(4) = {0, b, 0};
Point(5) = {0, a, 0};
Line(1) = {2, 3};
Circle(2) = {3, 1, 4};
Line(3) = {4, 5};
Circle(4) = {5, 1, 2};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
out[] = Extrude {0, 0, L} { Surface{1}; };
// out[0]: the end z = L, out[1]: the volume, out[2..5]: the sides swept by curves 1..4.
Physical Surface("symmetry_y") = {out[2]};
Physical Surface("outer") = {out[3]};
Physical Surface("symmetry_x") = {out[4]};
Physical Surface("inner") = {out[5]};
Physical Surface("ends") = {1, out[0]};
Physical Volume("wall") = {out[1]};
