// An elastic block [-4, 4] × [0, 4] for examples/problems/indenter.wf, graded towards the
// middle of its top, where the cylinder presses: element size hf there (default 0.01), 0.5
// far away. P2 triangles; groups `top`, `base`, `sides`, `body`.
// Made with:  gmsh indenter.geo -2 -setnumber hf 0.01 -format msh41 -o indenter_hf010.msh (and hf
// 0.02, 0.005 for indenter_hf020.msh, indenter_hf005.msh)
DefineConstant[ hf = 0.01 ];
W = 4; H = 4; hc = 0.5;
Point(1) = {-W, 0, 0, hc}; Point(2) = {W, 0, 0, hc}; Point(3) = {W, H, 0, hc};
Point(4) = {0, H, 0, hf}; Point(5) = {-W, H, 0, hc};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 5}; Line(5) = {5, 1};
Curve Loop(1) = {1, 2, 3, 4, 5};
Plane Surface(1) = {1};
// Size hf within the contact zone's box, growing away from it.
Field[1] = Box;
Field[1].VIn = hf; Field[1].VOut = hc;
Field[1].XMin = -0.16; Field[1].XMax = 0.16; Field[1].YMin = H - 0.08; Field[1].YMax = H;
Field[1].Thickness = 1.5;
Background Field = 1;
Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromPoints = 0;
Physical Curve("base") = {1};
Physical Curve("sides") = {2, 5};
Physical Curve("top") = {3, 4};
Physical Surface("body") = {1};
Mesh.ElementOrder = 2;
Mesh.Algorithm = 6;
