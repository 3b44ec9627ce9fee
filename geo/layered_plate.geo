// A steel plate bonded to a soft layer: 0.4 x 0.4 m, a 10 mm rubber-like layer (volume "rubber", z in
// [0, 0.01]) under 15 mm of steel ("steel"), meshed as one body (the layers share their interface).
// Groups: "contact" the layer's underside (z = 0), "top" the steel's upper face. Element size h.
SetFactory("OpenCASCADE");
If (!Exists(h))
  h = 0.008;
EndIf
side = 0.4;
layer = 0.01;
plate = 0.015;
tol = 1e-6;
Box(1) = {0, 0, 0, side, side, layer};
Box(2) = {0, 0, layer, side, side, plate};
BooleanFragments{ Volume{1}; Delete; }{ Volume{2}; Delete; }
Mesh.MeshSizeMax = h;
Physical Surface("contact") = Surface In BoundingBox {-tol, -tol, -tol, side + tol, side + tol, tol};
Physical Surface("top") = Surface In BoundingBox {-tol, -tol, layer + plate - tol, side + tol, side + tol, layer + plate + tol};
Physical Volume("rubber") = {1};
Physical Volume("steel") = {2};
