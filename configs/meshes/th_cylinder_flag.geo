// Turek-Hron 2006 channel [0, 2.5] x [0, 0.41] with the cylinder r = 0.05 at (0.2, 0.2)
// and the flag 0.35 x 0.02 (faces y = 0.19 and 0.21, free end at x = 0.6) as a hole.
// CFD1-3 treat the flag as a rigid wall; FSI1-3 use "flag" as the Nitsche interface.
// Parameters (gmsh -setnumber NAME VALUE):
//   h    element size far from the body
//   hc   element size on the cylinder and the flag (default h / 5)
//   hw   element size in the near wake x < 1.2 (default h / 2)
//   algorithm  gmsh 2D algorithm (default 6; 5 gives another layout of the same sizes)
//   nflag, nflagt  conforming flag (default 0 = off): nflag uniform cells along each flag face
//              (y = 0.19, 0.21) and nflagt across its free end x = 0.6, so that the flag nodes
//              are those of the solid's rectangle mesh with elements [nflag, nflagt]. The faces
//              start at the cylinder, x = 0.2 + sqrt(0.05^2 - 0.01^2) = 0.24898979: a solid
//              with origin x 0.24899 is 2.05e-7 off there (docs/fsi.md).
// Physical groups: inlet (x = 0), outlet (x = 2.5), walls (y = 0, 0.41), cylinder, flag, fluid.
SetFactory("OpenCASCADE");
DefineConstant[ h = 0.04 ];
DefineConstant[ hc = h / 5 ];
DefineConstant[ hw = h / 2 ];
DefineConstant[ algorithm = 6 ];
DefineConstant[ nflag = 0 ];
DefineConstant[ nflagt = 0 ];
L = 2.5; H = 0.41; xc = 0.2; yc = 0.2; r = 0.05;
eps = 1e-6;

Rectangle(1) = {0, 0, 0, L, H};
Disk(2) = {xc, yc, 0, r, r};
Rectangle(3) = {xc, 0.19, 0, 0.6 - xc, 0.02};
BooleanUnion(4) = { Surface{2}; Delete; }{ Surface{3}; Delete; };
BooleanDifference(5) = { Surface{1}; Delete; }{ Surface{4}; Delete; };

inlet() = Curve In BoundingBox{-eps, -eps, -eps, eps, H + eps, eps};
outlet() = Curve In BoundingBox{L - eps, -eps, -eps, L + eps, H + eps, eps};
bottom() = Curve In BoundingBox{-eps, -eps, -eps, L + eps, eps, eps};
top() = Curve In BoundingBox{-eps, H - eps, -eps, L + eps, H + eps, eps};
cylinder() = Curve In BoundingBox{xc - r - eps, yc - r - eps, -eps, 0.2489898 + 1e-5, yc + r + eps, eps};
flag() = Curve In BoundingBox{0.2489898 - 1e-5, 0.19 - eps, -eps, 0.6 + eps, 0.21 + eps, eps};
// The curve sets may overlap at the flag root; keep the cylinder arcs only (x < 0.24899).
cylinder() -= flag();
If (nflag > 0)
  flag_faces() = Curve In BoundingBox{0.2489898 - 1e-5, 0.19 - eps, -eps, 0.6 + eps, 0.19 + eps, eps};
  flag_faces() += Curve In BoundingBox{0.2489898 - 1e-5, 0.21 - eps, -eps, 0.6 + eps, 0.21 + eps, eps};
  Transfinite Curve{flag_faces()} = nflag + 1;
EndIf
If (nflagt > 0)
  flag_end() = Curve In BoundingBox{0.6 - eps, 0.19 - eps, -eps, 0.6 + eps, 0.21 + eps, eps};
  Transfinite Curve{flag_end()} = nflagt + 1;
EndIf

Field[1] = Distance;
Field[1].CurvesList = {cylinder(), flag()};
Field[1].NumPointsPerCurve = 200;
Field[2] = Threshold;
Field[2].InField = 1;
Field[2].SizeMin = hc;
Field[2].SizeMax = h;
Field[2].DistMin = 0.02;
Field[2].DistMax = 0.4;
Field[3] = Box;
Field[3].VIn = hw;
Field[3].VOut = h;
Field[3].XMin = 0.1;
Field[3].XMax = 1.2;
Field[3].YMin = 0.05;
Field[3].YMax = 0.36;
Field[3].Thickness = 0.2;
Field[4] = Min;
Field[4].FieldsList = {2, 3};
Background Field = 4;
Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromPoints = 0;
Mesh.MeshSizeFromCurvature = 0;
Mesh.Algorithm = algorithm;       // 6 frontal-Delaunay (default), 5 Delaunay, 1 MeshAdapt: another layout of the same sizes

Physical Curve("inlet") = {inlet()};
Physical Curve("outlet") = {outlet()};
Physical Curve("walls") = {bottom(), top()};
Physical Curve("cylinder") = {cylinder()};
Physical Curve("flag") = {flag()};
Physical Surface("fluid") = {5};
