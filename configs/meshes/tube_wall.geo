// The wall of the elastic tube as quadratic tetrahedra (solid_server's `solid.mesh.geo`, element
// tet10): the annular cylinder ri <= r <= ro, 0 <= z <= L, along +z from the origin.
// Physical groups: wall (volume), inner (r = ri, the coupling interface), outer (r = ro),
// start (z = 0), end (z = L): the face sets of solid_server's built-in tube.
// Parameters (gmsh -setnumber): ri (default 0.5), ro (0.6), L (5), h (element size, default
// (ro - ri) / 2). Order 2 (gmsh -order 2) puts the midpoints of the curved faces on the circles.
SetFactory("OpenCASCADE");
If (!Exists(ri))
  ri = 0.5;
EndIf
If (!Exists(ro))
  ro = 0.6;
EndIf
If (!Exists(L))
  L = 5;
EndIf
If (!Exists(h))
  h = (ro - ri) / 2;
EndIf
Cylinder(1) = {0, 0, 0, 0, 0, L, ro};
Cylinder(2) = {0, 0, 0, 0, 0, L, ri};
BooleanDifference(3) = {Volume{1}; Delete;}{Volume{2}; Delete;};
e = 1e-6 * L;
start() = Surface In BoundingBox{-ro - e, -ro - e, -e, ro + e, ro + e, e};
end() = Surface In BoundingBox{-ro - e, -ro - e, L - e, ro + e, ro + e, L + e};
inner() = Surface In BoundingBox{-ri - e, -ri - e, -e, ri + e, ri + e, L + e};
outer() = Surface{:};
outer() -= start();
outer() -= end();
outer() -= inner();
Physical Volume("wall") = {3};
Physical Surface("inner") = {inner()};
Physical Surface("outer") = {outer()};
Physical Surface("start") = {start()};
Physical Surface("end") = {end()};
Mesh.CharacteristicLengthMin = h;
Mesh.CharacteristicLengthMax = h;
