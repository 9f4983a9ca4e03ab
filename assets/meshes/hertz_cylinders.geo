// Halves of two Hertz cylinders (plane strain), x >= 0: the upper of radius R1 centred at
// (0, R1), touching y = 0 at the origin, and the lower of radius R2 centred at (0, -R2 - gap),
// a gap below it (the two meshes share no node). Cells have size hc within `zone` of the
// contact point and grow linearly outside it, up to hfar; each level halves every size.
// Make a level with:  gmsh -2 -setnumber level L hertz_cylinders.geo -o hertz_cylinders_L.msh
SetFactory("OpenCASCADE");
DefineConstant[ level = 0 ];
R1 = 10;
R2 = 20;
gap = 0.001;
hc = 0.2 / 2^level;      // in the contact zone
zone = 1.5;             // radius of the zone of size hc (contact half-width <= 1.25)
slope = 0.25 / 2^level;   // growth of the cell size with the distance to the zone
hfar = 2.0 / 2^level;
Disk(1) = {0, R1, 0, R1};
Rectangle(2) = {0, 0, 0, R1, 2*R1};
BooleanIntersection(3) = { Surface{1}; Delete; }{ Surface{2}; Delete; };
Disk(4) = {0, -R2 - gap, 0, R2};
Rectangle(5) = {0, -2*R2 - gap, 0, R2, 2*R2};
BooleanIntersection(6) = { Surface{4}; Delete; }{ Surface{5}; Delete; };
Physical Surface("upper") = {3};
Physical Surface("lower") = {6};
sym() = Curve In BoundingBox{-1e-6, -2*R2 - gap - 1e-6, -1, 1e-6, 2*R1 + 1e-6, 1};
upper() = Curve In BoundingBox{-1e-6, -1e-6, -1, R1 + 1e-6, 2*R1 + 1e-6, 1};
lower() = Curve In BoundingBox{-1e-6, -2*R2 - gap - 1e-6, -1, R2 + 1e-6, -gap + 1e-6, 1};
upper() -= sym();
lower() -= sym();
Physical Curve("symmetry_x") = {sym()};
Physical Curve("contact_upper") = {upper()};
Physical Curve("contact_lower") = {lower()};
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
