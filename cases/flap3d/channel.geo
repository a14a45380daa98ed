// The flap3d channel [0, 1.2] x [0, 0.4] x [0, 0.4] m (flow along x, floor z = 0) WITHOUT the
// flap: the fluid mesh fills the flap's region, which the immersed flap overlaps
// (cases/flap3d.yaml: the flap [0.3, 0.34] x [0.1, 0.3] x [0, 0.2] m). Physical groups:
// inlet (x = 0), outlet (x = 1.2), walls (the floor, the top and the two sides), fluid.
// Sizes: lc_flap in a box around the flap and its range of motion (a Box field with a
// transition layer), lc_far (capped by the case's mesh.size through Mesh.MeshSizeMax)
// elsewhere. Each mesh.level halves every size.
SetFactory("OpenCASCADE");
lc_far = 1.0;
lc_flap = 0.02;   // half the flap's thickness at level 0

Box(1) = {0, 0, 0, 1.2, 0.4, 0.4};

Field[1] = Box;
Field[1].VIn = lc_flap;
Field[1].VOut = lc_far;
Field[1].XMin = 0.26;
Field[1].XMax = 0.42;
Field[1].YMin = 0.06;
Field[1].YMax = 0.34;
Field[1].ZMin = 0.0;
Field[1].ZMax = 0.24;
Field[1].Thickness = 0.1;
Background Field = 1;
Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromPoints = 0;

eps = 1e-6;
inlet[] = Surface In BoundingBox {-eps, -eps, -eps, eps, 0.4 + eps, 0.4 + eps};
outlet[] = Surface In BoundingBox {1.2 - eps, -eps, -eps, 1.2 + eps, 0.4 + eps, 0.4 + eps};
all[] = Boundary{ Volume{1}; };
walls[] = all[];
walls[] -= inlet[];
walls[] -= outlet[];
Physical Surface("inlet") = {inlet[]};
Physical Surface("outlet") = {outlet[]};
Physical Surface("walls") = {walls[]};
Physical Volume("fluid") = {1};
