// The 2D analogue of the elastic tube (configs/tube_2d.yaml): the half channel [0, L] x [0, R]
// of a planar channel of half-width R, the axis y = 0 a symmetry line.
// Physical groups: fluid (surface), inlet (x = 0), outlet (x = L), axis (y = 0, symmetry),
// wall (y = R, the coupling interface).
// Parameters (gmsh -setnumber): R (default 0.5), L (default 5), h (element size, default R / 4),
// level (each level halves h).
SetFactory("OpenCASCADE");
If (!Exists(R))
  R = 0.5;
EndIf
If (!Exists(L))
  L = 5;
EndIf
If (!Exists(h))
  h = R / 4;
EndIf
If (!Exists(level))
  level = 0;
EndIf
Rectangle(1) = {0, 0, 0, L, R};
e = 1e-6 * L;
inlet() = Curve In BoundingBox{-e, -e, -e, e, R + e, e};
outlet() = Curve In BoundingBox{L - e, -e, -e, L + e, R + e, e};
axis() = Curve In BoundingBox{-e, -e, -e, L + e, e, e};
wall() = Curve In BoundingBox{-e, R - e, -e, L + e, R + e, e};
Physical Surface("fluid") = {1};
Physical Curve("inlet") = {inlet()};
Physical Curve("outlet") = {outlet()};
Physical Curve("axis") = {axis()};
Physical Curve("wall") = {wall()};
Mesh.MeshSizeMin = h / 2^level;
Mesh.MeshSizeMax = h / 2^level;
Mesh.Algorithm = 6;
