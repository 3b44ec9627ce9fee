// Split ring (OpenCASCADE): an aluminium annulus, outer radius 0.3 m, inner 0.15 m, height 0.15 m,
// cut through on one side by a 4 cm slot and turned by 0.3 rad about the z axis. It stands on the
// plane; its top face is moved by a prescribed displacement (down and sideways), the rest is free.
// Γc (z = 0) is a slotted annulus: curved outer and inner rims, two straight slot edges at an angle
// to the partition's rectangles, and no point more than 0.15 m from a free edge.
// Usage: gmsh -3 -setnumber h 0.03 ring.geo -o ring.msh
// Physical groups: top (z = 0.15), contact (z = 0), free (the rest), body.
SetFactory("OpenCASCADE");
If (!Exists(h))
  h = 0.03;
EndIf
R = 0.3; r = 0.15; H = 0.15; eps = 1e-6;
Cylinder(1) = {0, 0, 0, 0, 0, H, R};
Cylinder(2) = {0, 0, -1, 0, 0, H + 2, r};
Box(3) = {0.1, -0.02, -1, 1, 0.04, H + 2};
BooleanDifference(4) = { Volume{1}; Delete; }{ Volume{2, 3}; Delete; };
Rotate {{0, 0, 1}, {0, 0, 0}, 0.3} { Volume{4}; }
Mesh.MeshSizeMin = h;
Mesh.MeshSizeMax = h;
top() = Surface In BoundingBox {-R - eps, -R - eps, H - eps, R + eps, R + eps, H + eps};
contact() = Surface In BoundingBox {-R - eps, -R - eps, -eps, R + eps, R + eps, eps};
free() = Surface{:};
free() -= {top(), contact()};
Physical Surface("top") = {top()};
Physical Surface("contact") = {contact()};
Physical Surface("free") = {free()};
Physical Volume("body") = {Volume{:}};
