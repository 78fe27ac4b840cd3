// DFG 3D flow around a cylinder (Schafer & Turek 1996): channel [0, 2.5] x [0, 0.41] x [0, 0.41],
// circular cylinder D = 0.1 with its axis along z through the whole height, centre (0.5, 0.2).
// Physical groups: fluid (volume), inlet (x = 0), outlet (x = 2.5), walls (y = 0, y = H,
// z = 0, z = H), cylinder.
// Parameters (gmsh -setnumber): h (element size far away), level (each level halves every size:
// h / 2^level, hc / 2^level), hc (size on the cylinder, default h / 4).
// Order 2 (gmsh -order 2) puts the edge midpoints on the cylinder: the elements are curved.
SetFactory("OpenCASCADE");
If (!Exists(h))
  h = 0.1;
EndIf
If (!Exists(level))
  level = 0;
EndIf
If (!Exists(hc))
  hc = h / 4;
EndIf
hf = h / 2^level;
hcf = hc / 2^level;
H = 0.41;
Box(1) = {0, 0, 0, 2.5, H, H};
Cylinder(2) = {0.5, 0.2, 0, 0, 0, H, 0.05};
BooleanDifference(3) = { Volume{1}; Delete; }{ Volume{2}; Delete; };
e = 1e-6;
inlet() = Surface In BoundingBox{-e, -e, -e, e, H + e, H + e};
outlet() = Surface In BoundingBox{2.5 - e, -e, -e, 2.5 + e, H + e, H + e};
cyl() = Surface In BoundingBox{0.45 - e, 0.15 - e, -e, 0.55 + e, 0.25 + e, H + e};
all() = Surface{:};
walls() = all();
walls() -= inlet();
walls() -= outlet();
walls() -= cyl();
Physical Volume("fluid") = {3};
Physical Surface("inlet") = {inlet()};
Physical Surface("outlet") = {outlet()};
Physical Surface("walls") = {walls()};
Physical Surface("cylinder") = {cyl()};
// Sizes: hcf on the cylinder, growing linearly to hf at distance 0.3.
Field[1] = Distance;
Field[1].SurfacesList = {cyl()};
Field[2] = Threshold;
Field[2].InField = 1;
Field[2].SizeMin = hcf;
Field[2].SizeMax = hf;
Field[2].DistMin = 0;
Field[2].DistMax = 0.3;
Background Field = 2;
Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromPoints = 0;
Mesh.MeshSizeFromCurvature = 0;
