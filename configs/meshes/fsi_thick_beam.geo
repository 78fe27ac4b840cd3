// Kadapa (seed paper) example 1: thick beam in cross flow (CGS units).
// Channel [0, 1.8] x [0, 0.6]; beam [0.465, 0.515] x [0, 0.3] clamped to the bottom wall, as a hole.
// Parameters (gmsh -setnumber NAME VALUE):
//   h    element size far from the beam
//   hb   element size on the beam (default h / 4)
// Physical groups: inlet (x = 0), outlet (x = 1.8), walls (y = 0, 0.6), beam (the three wet faces), fluid.
SetFactory("OpenCASCADE");
DefineConstant[ h = 0.04 ];
DefineConstant[ hb = h / 4 ];
L = 1.8; H = 0.6; x0 = 0.465; x1 = 0.515; hbeam = 0.3;
eps = 1e-6;
Rectangle(1) = {0, 0, 0, L, H};
Rectangle(2) = {x0, 0, 0, x1 - x0, hbeam};
BooleanDifference(3) = { Surface{1}; Delete; }{ Surface{2}; Delete; };

inlet() = Curve In BoundingBox{-eps, -eps, -eps, eps, H + eps, eps};
outlet() = Curve In BoundingBox{L - eps, -eps, -eps, L + eps, H + eps, eps};
bottom() = Curve In BoundingBox{-eps, -eps, -eps, L + eps, eps, eps};
top() = Curve In BoundingBox{-eps, H - eps, -eps, L + eps, H + eps, eps};
beam() = Curve In BoundingBox{x0 - eps, -eps, -eps, x1 + eps, hbeam + eps, eps};

Field[1] = Distance;
Field[1].CurvesList = {beam()};
Field[1].NumPointsPerCurve = 200;
Field[2] = Threshold;
Field[2].InField = 1;
Field[2].SizeMin = hb;
Field[2].SizeMax = h;
Field[2].DistMin = 0.02;
Field[2].DistMax = 0.3;
Background Field = 2;
Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromPoints = 0;
Mesh.MeshSizeFromCurvature = 0;
Mesh.Algorithm = 6;

Physical Curve("inlet") = {inlet()};
Physical Curve("outlet") = {outlet()};
Physical Curve("walls") = {bottom(), top()};
Physical Curve("beam") = {beam()};
Physical Surface("fluid") = {3};
