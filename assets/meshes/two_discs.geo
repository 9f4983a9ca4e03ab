// Two discs of radius 10 centred at (-11, 0) and (11, 0), 2 apart, for the two-body GetFEM
// cross-check (scripts/getfem/two_discs.wf, scripts/getfem/two_discs.py). Straight P1 triangles,
// finer where the discs face each other (hc at the points (-1, 0) and (1, 0), hfar opposite).
// Make it with:  gmsh -2 -format msh22 two_discs.geo -o two_discs_p1.msh
// (-setnumber order 2 for isoparametric P2 cells: two_discs_p2.msh).
DefineConstant[ order = 1 ];
R = 10;
c = 11;
hc = 1;
hfar = 3.5;
hside = 2.5;
// Left disc: centre 1, points east (2, facing the right disc), north, west, south.
Point(1) = {-c, 0, 0, hfar};
Point(2) = {-c + R, 0, 0, hc};
Point(3) = {-c, R, 0, hside};
Point(4) = {-c - R, 0, 0, hfar};
Point(5) = {-c, -R, 0, hside};
Circle(1) = {2, 1, 3};
Circle(2) = {3, 1, 4};
Circle(3) = {4, 1, 5};
Circle(4) = {5, 1, 2};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
// Right disc: the mirror image (x -> -x).
Point(11) = {c, 0, 0, hfar};
Point(12) = {c - R, 0, 0, hc};
Point(13) = {c, R, 0, hside};
Point(14) = {c + R, 0, 0, hfar};
Point(15) = {c, -R, 0, hside};
Circle(11) = {12, 11, 13};
Circle(12) = {13, 11, 14};
Circle(13) = {14, 11, 15};
Circle(14) = {15, 11, 12};
Curve Loop(11) = {11, 12, 13, 14};
Plane Surface(11) = {11};
Physical Surface("left") = {1};
Physical Surface("right") = {11};
Physical Curve("boundary_left") = {1, 2, 3, 4};
Physical Curve("boundary_right") = {11, 12, 13, 14};
Mesh.Algorithm = 6;
Mesh.ElementOrder = order;
Mesh.MshFileVersion = 2.2;
