// Slotted block on a rotated footprint (OpenCASCADE): a block 1.6 x 0.8 x 0.4 m with a slot
// 0.2 m wide and 0.15 m deep cut across its underside, the whole body turned by `angle` degrees
// about the vertical axis. Γc (z = 0) is two rectangles at an angle to the partition's grid: the
// cells are cut along slanted edges, and cells straddling the slot hold two disconnected pieces.
// Usage: gmsh -3 -setnumber h 0.05 -setnumber angle 25 slotted.geo -o slotted.msh
// Physical groups: clamped (the end face at local x = 0), load_top (z = 0.4), load_end (local
// x = 1.6), contact (z = 0), free, body.
SetFactory("OpenCASCADE");
If (!Exists(h))
  h = 0.05;
EndIf
If (!Exists(angle))
  angle = 25;
EndIf
L = 1.6; W = 0.8; T = 0.4; s = 0.2; d = 0.15; eps = 1e-6;
Box(1) = {0, 0, 0, L, W, T};
Box(2) = {(L - s) / 2, -0.1, -0.1, s, W + 0.2, d + 0.1};
v() = BooleanDifference{ Volume{1}; Delete; }{ Volume{2}; Delete; };
Mesh.MeshSizeMin = h;
Mesh.MeshSizeMax = h;
// Groups before turning: bounding boxes are axis-aligned here.
clamped() = Surface In BoundingBox {-eps, -eps, -eps, eps, W + eps, T + eps};
tip() = Surface In BoundingBox {L - eps, -eps, -eps, L + eps, W + eps, T + eps};
top() = Surface In BoundingBox {-eps, -eps, T - eps, L + eps, W + eps, T + eps};
contact() = Surface In BoundingBox {-eps, -eps, -eps, L + eps, W + eps, eps};
free() = Surface{:};
free() -= {clamped(), tip(), top(), contact()};
Rotate {{0, 0, 1}, {0, 0, 0}, angle * Pi / 180} { Volume{v()}; }
Physical Surface("clamped") = {clamped()};
Physical Surface("load_top") = {top()};
Physical Surface("load_end") = {tip()};
Physical Surface("contact") = {contact()};
Physical Surface("free") = {free()};
Physical Volume("body") = {v()};
