// Turek-Hron flag for the CSM benchmarks extruded in z, as quadratic tetrahedra (gmsh):
// [0.24899, 0.6] x [0.19, 0.21] x [0, t]. Physical groups: volume "flag"; surfaces "clamped"
// (x = 0.24899), "sides" (z = 0 and z = t), "wet" (the other three). Parameters (gmsh
// -setnumber): h (element size, default 0.01), t (thickness, default 0.01). The shipped
// csm_flag_3d.msh is the default:
//   gmsh -3 -order 2 -format msh22 csm_flag_3d.geo -o csm_flag_3d.msh
// finer: gmsh -3 -order 2 -format msh22 -setnumber h 0.005 csm_flag_3d.geo -o csm_flag_3d_h005.msh
SetFactory("OpenCASCADE");
If (!Exists(h))
  h = 0.01;
EndIf
If (!Exists(t))
  t = 0.01;
EndIf
x0 = 0.24899; x1 = 0.6; y0 = 0.19; y1 = 0.21;
Box(1) = {x0, y0, 0, x1 - x0, y1 - y0, t};
e = 1e-6;
clamped() = Surface In BoundingBox{x0 - e, y0 - e, -e, x0 + e, y1 + e, t + e};
back() = Surface In BoundingBox{x0 - e, y0 - e, -e, x1 + e, y1 + e, e};
front() = Surface In BoundingBox{x0 - e, y0 - e, t - e, x1 + e, y1 + e, t + e};
all() = Surface{:};
wet() = all();
wet() -= clamped();
wet() -= back();
wet() -= front();
Physical Volume("flag") = {1};
Physical Surface("clamped") = {clamped()};
Physical Surface("sides") = {back(), front()};
Physical Surface("wet") = {wet()};
Mesh.CharacteristicLengthMax = h;
Mesh.CharacteristicLengthMin = h;
Mesh.ElementOrder = 2;
