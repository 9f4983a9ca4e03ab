// The bouncing sphere's ball (radius 10, centred at (0, 0, 12)) with cells graded towards its
// lowest point (0, 0, 2), where it first touches the plane z = 0: size hc within `zone` of
// it, growing linearly outside, up to hfar.
// Make it with:  gmsh -3 sphere_graded.geo -o sphere_graded.msh
// and run:       signorini run sphere --mesh assets/meshes/sphere_graded.msh
// (no `contact` group: the case takes the facets facing the plane, n_z < 0)
SetFactory("OpenCASCADE");
R = 10;
hc = 0.5;
zone = 3.0;
slope = 0.3;
hfar = 2.5;
Sphere(1) = {0, 0, R + 2, R};
Physical Volume("body") = {1};
Field[1] = MathEval;
Field[1].F = Sprintf("min(%g + %g*Max(Sqrt(x^2 + y^2 + (z - 2)^2) - %g, 0), %g)", hc, slope, zone, hfar);
Background Field = 1;
Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromPoints = 0;
Mesh.MeshSizeFromCurvature = 0;
Mesh.ElementOrder = 2;
Mesh.HighOrderOptimize = 2;
Mesh.MshFileVersion = 4.1;
Mesh.Binary = 1;
