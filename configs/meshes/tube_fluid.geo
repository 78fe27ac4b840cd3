// The fluid of the elastic tube (Formaggia, Gerbeau, Nobile & Quarteroni 2001): a straight
// circular cylinder of radius R and length L along +z from the origin.
// Physical groups: fluid (volume), inlet (z = 0), outlet (z = L), wall (the lateral surface,
// the coupling interface).
// Parameters (gmsh -setnumber): R (default 0.5), L (default 5), h (element size, default R / 2),
// level (each level halves h). Order 2 (gmsh -order 2) puts the wall's midpoints on the circle.
SetFactory("OpenCASCADE");
If (!Exists(R))
  R = 0.5;
EndIf
If (!Exists(L))
  L = 5;
EndIf
If (!Exists(h))
  h = R / 2;
EndIf
If (!Exists(level))
  level = 0;
EndIf
Cylinder(1) = {0, 0, 0, 0, 0, L, R};
e = 1e-6 * L;
inlet() = Surface In BoundingBox{-R - e, -R - e, -e, R + e, R + e, e};
outlet() = Surface In BoundingBox{-R - e, -R - e, L - e, R + e, R + e, L + e};
wall() = Surface{:};
wall() -= inlet();
wall() -= outlet();
Physical Volume("fluid") = {1};
Physical Surface("inlet") = {inlet()};
Physical Surface("outlet") = {outlet()};
Physical Surface("wall") = {wall()};
Mesh.MeshSizeMin = h / 2^level;
Mesh.MeshSizeMax = h / 2^level;
