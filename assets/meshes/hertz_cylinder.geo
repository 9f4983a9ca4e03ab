// Half of the Hertz cylinder (plane strain): the disc of radius 10 centred at (0, 10), x >= 0,
// touching the plane y = 0 at the origin. Cells have size hc within `zone` of the contact point
// and grow linearly outside it, up to hfar; each level halves every size.
// Make a level with:  gmsh -2 -setnumber level L hertz_cylinder.geo -o hertz_cylinder_L.msh
SetFactory("OpenCASCADE");
DefineConstant[ level = 0 ];
R = 10;
hc = 0.2 / 2^level;      // in the contact zone
zone = 1.5;             // radius of the zone of size hc (contact radius <= 1.25)
slope = 0.25 / 2^level;   // growth of the cell size with the distance to the zone
hfar = 2.0 / 2^level;
Disk(1) = {0, R, 0, R};
Rectangle(2) = {0, 0, 0, R, 2*R};
BooleanIntersection(3) = { Surface{1}; Delete; }{ Surface{2}; Delete; };
Physical Surface("body") = {3};
sym() = Curve In BoundingBox{-1e-6, -1e-6, -1, 1e-6, 2*R + 1e-6, 1};
all() = Curve In BoundingBox{-1e-6, -1e-6, -1, R + 1e-6, 2*R + 1e-6, 1};
Physical Curve("symmetry_x") = {sym()};
all() -= sym();
Physical Curve("contact") = {all()};
Field[1] = MathEval;
Field[1].F = Sprintf("min(%g + %g*Max(Sqrt(x^2 + y^2) - %g, 0), %g)", hc, slope, zone, hfar);
Background Field = 1;
Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromPoints = 0;
Mesh.MeshSizeFromCurvature = 0;
Mesh.ElementOrder = 2;
Mesh.HighOrderOptimize = 2;
Mesh.MshFileVersion = 4.1;
Mesh.Binary = 1;
