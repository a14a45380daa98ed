// Block [0,1] x [0,2] x [0,1] (volume 2, surface 10), for the mesh tests.
SetFactory("OpenCASCADE");
Box(1) = {0, 0, 0, 1, 2, 1};
Physical Volume("block", 7) = {1};
Physical Surface("sides", 8) = {1, 2, 3, 4, 5, 6};
