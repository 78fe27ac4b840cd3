// Turek-Hron flag for the CSM benchmarks as a structured quad mesh (gmsh):
// [0.24899, 0.6] x [0.19, 0.21], physical groups: surface "flag", lines "clamped" (x = 0.24899),
// "wet" (the other three sides). Regenerate: gmsh -2 -format msh22 csm_flag.geo -o csm_flag.msh
nx = 160; ny = 8;
Point(1) = {0.24899, 0.19, 0};
Point(2) = {0.6, 0.19, 0};
Point(3) = {0.6, 0.21, 0};
Point(4) = {0.24899, 0.21, 0};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Transfinite Curve{1, 3} = nx + 1;
Transfinite Curve{2, 4} = ny + 1;
Transfinite Surface{1};
Recombine Surface{1};
Physical Surface("flag") = {1};
Physical Curve("clamped") = {4};
Physical Curve("wet") = {1, 2, 3};
