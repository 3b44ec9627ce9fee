// U-shaped footprint (OpenCASCADE): a back (0,0.5)x(0,1.5) and two legs (0.5,2)x(0,0.5) and
// (0.5,2)x(1,1.5), extruded to height 0.5 m. Γc (z = 0) is the non-convex U: grid cells
// straddling the gap between the legs hold two disconnected pieces and are split.
// Usage: gmsh -3 -setnumber h 0.1 ufoot.geo -o ufoot.msh
// Physical groups: clamped (x=0, Γu), load_top (z=0.5), load_end (x=2, both leg ends),
// contact (z=0, Γc), free (everything else), body.
SetFactory("OpenCASCADE");
If (!Exists(h))
  h = 0.1;
EndIf
eps = 1e-6;
Box(1) = {0, 0, 0, 0.5, 1.5, 0.5};
Box(2) = {0.5, 0, 0, 1.5, 0.5, 0.5};
Box(3) = {0.5, 1, 0, 1.5, 0.5, 0.5};
v() = BooleanUnion{ Volume{1}; Delete; }{ Volume{2, 3}; Delete; };
Mesh.MeshSizeMin = h;
Mesh.MeshSizeMax = h;

clamped() = Surface In BoundingBox {-eps, -eps, -eps, eps, 1.5 + eps, 0.5 + eps};
top() = Surface In BoundingBox {-eps, -eps, 0.5 - eps, 2 + eps, 1.5 + eps, 0.5 + eps};
tip() = Surface In BoundingBox {2 - eps, -eps, -eps, 2 + eps, 1.5 + eps, 0.5 + eps};
contact() = Surface In BoundingBox {-eps, -eps, -eps, 2 + eps, 1.5 + eps, eps};
free() = Surface{:};
free() -= {clamped(), top(), tip(), contact()};
Physical Surface("clamped") = {clamped()};
Physical Surface("load_top") = {top()};
Physical Surface("load_end") = {tip()};
Physical Surface("contact") = {contact()};
Physical Surface("free") = {free()};
Physical Volume("body") = {v()};
