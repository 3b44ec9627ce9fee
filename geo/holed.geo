// Block with a vertical through hole (OpenCASCADE): (0,2)x(0,1)x(0,0.5) m minus a cylinder of
// radius 0.2 m around the axis x = 1.2, y = 0.5. Γc (z = 0) is a rectangle with a circular
// hole: grid cells around the hole are clipped to a polygonal ring and some are merged.
// Usage: gmsh -3 -setnumber h 0.1 holed.geo -o holed.msh
// Physical groups: clamped (x=0, Γu), load_top (z=0.5), load_end (x=2), contact (z=0, Γc),
// free (y=0, y=1 and the hole's wall), body.
SetFactory("OpenCASCADE");
If (!Exists(h))
  h = 0.1;
EndIf
eps = 1e-6;
Box(1) = {0, 0, 0, 2, 1, 0.5};
Cylinder(2) = {1.2, 0.5, -0.1, 0, 0, 0.7, 0.2};
v() = BooleanDifference{ Volume{1}; Delete; }{ Volume{2}; Delete; };
Mesh.MeshSizeMin = h;
Mesh.MeshSizeMax = h;

clamped() = Surface In BoundingBox {-eps, -eps, -eps, eps, 1 + eps, 0.5 + eps};
top() = Surface In BoundingBox {-eps, -eps, 0.5 - eps, 2 + eps, 1 + eps, 0.5 + eps};
tip() = Surface In BoundingBox {2 - eps, -eps, -eps, 2 + eps, 1 + eps, 0.5 + eps};
contact() = Surface In BoundingBox {-eps, -eps, -eps, 2 + eps, 1 + eps, eps};
free() = Surface{:};
free() -= {clamped(), top(), tip(), contact()};
Physical Surface("clamped") = {clamped()};
Physical Surface("load_top") = {top()};
Physical Surface("load_end") = {tip()};
Physical Surface("contact") = {contact()};
Physical Surface("free") = {free()};
Physical Volume("body") = {v()};
