// Two precast segments made with Gmsh: a prismatic one (0–1 m) and a tapered one whose
// soffit rises from 0 to 0.1 m over 1–2 m. Each segment is its own surface with its own
// nodes at the joint (x = 1 m), so segfem can put a dry joint between them.
// Mesh: gmsh -2 -order 2 gmsh-tapered.geo -format msh22 -o gmsh-tapered.msh
h = 0.5;
Point(1) = {0, 0, 0};
Point(2) = {1, 0, 0};
Point(3) = {1, h, 0};
Point(4) = {0, h, 0};
Point(5) = {1, 0, 0};
Point(6) = {2, 0.1, 0};
Point(7) = {2, h, 0};
Point(8) = {1, h, 0};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1};
Line(5) = {5, 6}; Line(6) = {6, 7}; Line(7) = {7, 8}; Line(8) = {8, 5};
Curve Loop(1) = {1, 2, 3, 4}; Plane Surface(1) = {1};
Curve Loop(2) = {5, 6, 7, 8}; Plane Surface(2) = {2};
Transfinite Curve{1, 3, 5, 7} = 9;
Transfinite Curve{2, 4, 6, 8} = 5;
Transfinite Surface{1}; Transfinite Surface{2};
Recombine Surface{1, 2};
Mesh.SecondOrderIncomplete = 1;   // 8-node quadrilaterals
Physical Surface("segment_a") = {1};
Physical Surface("segment_b") = {2};
Physical Curve("joint_a") = {2};
Physical Curve("joint_b") = {8};
Physical Curve("left_end") = {4};
Physical Curve("right_end") = {6};
Physical Curve("top") = {3, 7};
