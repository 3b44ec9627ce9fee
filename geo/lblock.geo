// L-shaped block (OpenCASCADE): a base (0,2)x(0,1)x(0,0.4) m with an upright
// (0,0.6)x(0,1)x(0.4,1.4) m on its clamped end. Γc is the whole bottom z = 0 (a rectangle);
// the upright makes the stiffness (and the contact pressure) strongly non-uniform along x.
// Usage: gmsh -3 -setnumber h 0.1 lblock.geo -o lblock.msh
// Physical groups: clamped (x=0, Γu), load_top (top of the base, z=0.4, x>0.6),
// load_end (x=2), contact (z=0, Γc), free (everything else), body.
SetFactory("OpenCASCADE");
If (!Exists(h))
  h = 0.1;
EndIf
eps = 1e-6;
Box(1) = {0, 0, 0, 2, 1, 0.4};
Box(2) = {0, 0, 0.4, 0.6, 1, 1.0};
v() = BooleanUnion{ Volume{1}; Delete; }{ Volume{2}; Delete; };
Mesh.MeshSizeMin = h;
Mesh.MeshSizeMax = h;

clamped() = Surface In BoundingBox {-eps, -eps, -eps, eps, 1 + eps, 1.4 + eps};
top() = Surface In BoundingBox {0.6 - eps, -eps, 0.4 - eps, 2 + eps, 1 + eps, 0.4 + eps};
tip() = Surface In BoundingBox {2 - eps, -eps, -eps, 2 + eps, 1 + eps, 0.4 + eps};
contact() = Surface In BoundingBox {-eps, -eps, -eps, 2 + eps, 1 + eps, eps};
free() = Surface{:};
free() -= {clamped(), top(), tip(), contact()};
Physical Surface("clamped") = {clamped()};
Physical Surface("load_top") = {top()};
Physical Surface("load_end") = {tip()};
Physical Surface("contact") = {contact()};
Physical Surface("free") = {free()};
Physical Volume("body") = {v()};
