// Turek-Hron flag as in the benchmark's geometry: clamped on the cylinder's arc (centre
// (0.2, 0.2), r = 0.05) instead of the straight edge x = 0.24899 of csm_flag.geo, free end at
// x = 0.6, faces y = 0.19 and 0.21; a structured quad mesh of nx x ny cells.
// Physical groups: surface "flag", curves "clamped" (the arc) and "wet" (the other three sides).
// Regenerate: gmsh -2 -format msh22 -setnumber nx 160 -setnumber ny 8 csm_flag_arc.geo -o csm_flag_arc.msh
DefineConstant[ nx = 160 ];
DefineConstant[ ny = 8 ];
x0 = 0.2 + Sqrt(0.05^2 - 0.01^2);   // 0.2489898: where the faces meet the cylinder
Point(1) = {x0, 0.19, 0};
Point(2) = {0.6, 0.19, 0};
Point(3) = {0.6, 0.21, 0};
Point(4) = {x0, 0.21, 0};
Point(5) = {0.2, 0.2, 0};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Circle(4) = {4, 5, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Transfinite Curve{1, 3} = nx + 1;
Transfinite Curve{2, 4} = ny + 1;
Transfinite Surface{1};
Recombine Surface{1};
Physical Surface("flag") = {1};
Physical Curve("clamped") = {4};
Physical Curve("wet") = {1, 2, 3};
