// An elastic ring (annulus) of outer radius 10 and inner radius 6 centred at (0, 12), for
// examples/problems/ring.wf. Curved P2 triangles; groups `outer`, `inner`, `body`.
// Make it with:  gmsh ring.geo -2 -format msh41 -o ring.msh
h = 1.5;
R = 10; r = 6;
Point(1) = {0, 12, 0, h};
Point(2) = {R, 12, 0, h};  Point(3) = {0, 12 + R, 0, h};  Point(4) = {-R, 12, 0, h};  Point(5) = {0, 12 - R, 0, h};
Point(6) = {r, 12, 0, h};  Point(7) = {0, 12 + r, 0, h};  Point(8) = {-r, 12, 0, h};  Point(9) = {0, 12 - r, 0, h};
Circle(1) = {2, 1, 3}; Circle(2) = {3, 1, 4}; Circle(3) = {4, 1, 5}; Circle(4) = {5, 1, 2};
Circle(5) = {6, 1, 7}; Circle(6) = {7, 1, 8}; Circle(7) = {8, 1, 9}; Circle(8) = {9, 1, 6};
Curve Loop(1) = {1, 2, 3, 4};
Curve Loop(2) = {5, 6, 7, 8};
Plane Surface(1) = {1, 2};
Physical Curve("outer") = {1, 2, 3, 4};
Physical Curve("inner") = {5, 6, 7, 8};
Physical Surface("body") = {1};
Mesh.ElementOrder = 2;
Mesh.Algorithm = 6;
