// Kadapa (seed paper) example 2: thin beam / idealised mitral valve of Gil et al. 2010, half
// domain with symmetry (CGS units). Channel [0, 8] x [0, 0.805] (symmetry line y = 0.805);
// leaflet 0.0212 thick, 0.7 long, centred on x = 2, clamped to the wall y = 0, as a hole.
// Parameters (gmsh -setnumber NAME VALUE):
//   h    element size far from the leaflet
//   hl   element size on the leaflet (default h / 10)
//   hw   element size in the region around the leaflet's sweep (default h / 3)
// Physical groups: inlet (x = 0), outlet (x = 8), wall (y = 0), symmetry (y = 0.805), leaflet, fluid.
SetFactory("OpenCASCADE");
DefineConstant[ h = 0.1 ];
DefineConstant[ hl = h / 10 ];
DefineConstant[ hw = h / 3 ];
L = 8.0; H = 0.805; t = 0.0212; len = 0.7; xc = 2.0;
eps = 1e-6;
Rectangle(1) = {0, 0, 0, L, H};
Rectangle(2) = {xc - t / 2, 0, 0, t, len};
BooleanDifference(3) = { Surface{1}; Delete; }{ Surface{2}; Delete; };

inlet() = Curve In BoundingBox{-eps, -eps, -eps, eps, H + eps, eps};
outlet() = Curve In BoundingBox{L - eps, -eps, -eps, L + eps, H + eps, eps};
wall() = Curve In BoundingBox{-eps, -eps, -eps, L + eps, eps, eps};
symmetry() = Curve In BoundingBox{-eps, H - eps, -eps, L + eps, H + eps, eps};
leaflet() = Curve In BoundingBox{xc - t / 2 - eps, -eps, -eps, xc + t / 2 + eps, len + eps, eps};

Field[1] = Distance;
Field[1].CurvesList = {leaflet()};
Field[1].NumPointsPerCurve = 400;
Field[2] = Threshold;
Field[2].InField = 1;
Field[2].SizeMin = hl;
Field[2].SizeMax = h;
Field[2].DistMin = 0.01;
Field[2].DistMax = 0.5;
Field[3] = Box;
Field[3].VIn = hw;
Field[3].VOut = h;
Field[3].XMin = 1.2;
Field[3].XMax = 3.5;
Field[3].YMin = 0;
Field[3].YMax = H;
Field[3].Thickness = 0.5;
Field[4] = Min;
Field[4].FieldsList = {2, 3};
Background Field = 4;
Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromPoints = 0;
Mesh.MeshSizeFromCurvature = 0;
Mesh.Algorithm = 6;

Physical Curve("inlet") = {inlet()};
Physical Curve("outlet") = {outlet()};
Physical Curve("wall") = {wall()};
Physical Curve("symmetry") = {symmetry()};
Physical Curve("leaflet") = {leaflet()};
Physical Surface("fluid") = {3};
