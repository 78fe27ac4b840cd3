// The elastic block of configs/block_3d.yaml (1 x 1 x 0.2 m, origin (-0.5, -0.5, 0)) as
// quadratic tetrahedra with straight edges, for scenes/block_3d_tet.yaml. Physical groups:
// volume "block"; surfaces "left" (x = -0.5), "bottom" (y = -0.5), "back" (z = 0), "front"
// (z = 0.2). Parameter h (gmsh -setnumber h H), default 0.25:
//   gmsh -3 -order 2 -format msh22 block_3d_tet.geo -o block_3d_tet.msh
SetFactory("OpenCASCADE");
If (!Exists(h))
  h = 0.25;
EndIf
Box(1) = {-0.5, -0.5, 0, 1, 1, 0.2};
e = 1e-6;
left() = Surface In BoundingBox{-0.5 - e, -0.5 - e, -e, -0.5 + e, 0.5 + e, 0.2 + e};
bottom() = Surface In BoundingBox{-0.5 - e, -0.5 - e, -e, 0.5 + e, -0.5 + e, 0.2 + e};
back() = Surface In BoundingBox{-0.5 - e, -0.5 - e, -e, 0.5 + e, 0.5 + e, e};
front() = Surface In BoundingBox{-0.5 - e, -0.5 - e, 0.2 - e, 0.5 + e, 0.5 + e, 0.2 + e};
Physical Volume("block") = {1};
Physical Surface("left") = {left()};
Physical Surface("bottom") = {bottom()};
Physical Surface("back") = {back()};
Physical Surface("front") = {front()};
Mesh.CharacteristicLengthMax = h;
Mesh.CharacteristicLengthMin = h;
Mesh.ElementOrder = 2;
