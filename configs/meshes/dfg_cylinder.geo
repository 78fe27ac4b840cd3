// Schafer-Turek 1996 DFG channel [0, 2.2] x [0, 0.41] with the cylinder r = 0.05 at (0.2, 0.2).
// Parameters (override with gmsh -setnumber NAME VALUE):
//   h       element size far from the cylinder
//   hc      element size on the cylinder (default h / 5)
//   hw      element size in the near wake x < 0.8 (default h / 2)
//   algorithm  gmsh 2D algorithm (default 6; 5 gives another layout of the same sizes)
// Physical groups: inlet (x = 0), outlet (x = 2.2), walls (y = 0, 0.41), cylinder, fluid.
DefineConstant[ h = 0.04 ];
DefineConstant[ hc = h / 5 ];
DefineConstant[ hw = h / 2 ];
DefineConstant[ algorithm = 6 ];
L = 2.2; H = 0.41; xc = 0.2; yc = 0.2; r = 0.05;

Point(1) = {0, 0, 0, h};
Point(2) = {L, 0, 0, h};
Point(3) = {L, H, 0, h};
Point(4) = {0, H, 0, h};
Point(5) = {xc, yc, 0, hc};
Point(6) = {xc + r, yc, 0, hc};
Point(7) = {xc, yc + r, 0, hc};
Point(8) = {xc - r, yc, 0, hc};
Point(9) = {xc, yc - r, 0, hc};

Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Circle(5) = {6, 5, 7};
Circle(6) = {7, 5, 8};
Circle(7) = {8, 5, 9};
Circle(8) = {9, 5, 6};

Curve Loop(1) = {1, 2, 3, 4};
Curve Loop(2) = {5, 6, 7, 8};
Plane Surface(1) = {1, 2};

// Grade the size from hc on the cylinder to hw in the near wake and h far away.
Field[1] = Distance;
Field[1].CurvesList = {5, 6, 7, 8};
Field[1].NumPointsPerCurve = 200;
Field[2] = Threshold;
Field[2].InField = 1;
Field[2].SizeMin = hc;
Field[2].SizeMax = h;
Field[2].DistMin = 0.5 * r;
Field[2].DistMax = 0.5;
Field[3] = Box;
Field[3].VIn = hw;
Field[3].VOut = h;
Field[3].XMin = 0.1;
Field[3].XMax = 0.9;
Field[3].YMin = 0.1;
Field[3].YMax = 0.3;
Field[3].Thickness = 0.2;
Field[4] = Min;
Field[4].FieldsList = {2, 3};
Background Field = 4;
Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromPoints = 0;
Mesh.MeshSizeFromCurvature = 0;
Mesh.Algorithm = algorithm;       // 6 frontal-Delaunay (default), 5 Delaunay, 1 MeshAdapt: another layout of the same sizes

Physical Curve("inlet") = {4};
Physical Curve("outlet") = {2};
Physical Curve("walls") = {1, 3};
Physical Curve("cylinder") = {5, 6, 7, 8};
Physical Surface("fluid") = {1};
