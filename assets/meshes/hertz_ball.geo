// A quarter of the Hertz ball: radius 10, centred at (0, 0, 10), x >= 0 and y >= 0, touching
// the plane z = 0 at the origin. Cells have size hc within `zone` of the contact point and grow
// linearly outside it, up to hfar; each level divides every size by √2.
// Make a level with:  gmsh -3 -setnumber level L hertz_ball.geo -o hertz_ball_L.msh
SetFactory("OpenCASCADE");
DefineConstant[ level = 0 ];
R = 10;
hc = 0.25 / Sqrt(2)^level;     // in the contact zone
zone = 1.3;                    // radius of the zone of size hc (Hertz's radius <= 1.25)
slope = 0.3 / Sqrt(2)^level;   // growth of the cell size with the distance to the zone
hfar = 3.0 / Sqrt(2)^level;
Sphere(1) = {0, 0, R, R};
Box(2) = {0, 0, 0, R, R, 2*R};
BooleanIntersection(3) = { Volume{1}; Delete; }{ Volume{2}; Delete; };
Physical Volume("body") = {3};
Physical Surface("symmetry_x") = Surface In BoundingBox{-1e-6, -1e-6, -1e-6, 1e-6, R + 1e-6, 2*R + 1e-6};
Physical Surface("symmetry_y") = Surface In BoundingBox{-1e-6, -1e-6, -1e-6, R + 1e-6, 1e-6, 2*R + 1e-6};
all() = Surface In BoundingBox{-1e-6, -1e-6, -1e-6, R + 1e-6, R + 1e-6, 2*R + 1e-6};
sym() = Surface In BoundingBox{-1e-6, -1e-6, -1e-6, 1e-6, R + 1e-6, 2*R + 1e-6};
sym() += Surface In BoundingBox{-1e-6, -1e-6, -1e-6, R + 1e-6, 1e-6, 2*R + 1e-6};
all() -= sym();
Physical Surface("contact") = {all()};
Field[1] = MathEval;
Field[1].F = Sprintf("min(%g + %g*Max(Sqrt(x^2 + y^2 + z^2) - %g, 0), %g)", hc, slope, zone, hfar);
Background Field = 1;
Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromPoints = 0;
Mesh.MeshSizeFromCurvature = 0;
Mesh.ElementOrder = 2;
Mesh.HighOrderOptimize = 2;
Mesh.MshFileVersion = 4.1;
Mesh.Binary = 1;
