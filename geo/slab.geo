// Thin slab on the foundation (OpenCASCADE): Lx x Ly x t, the four side faces clamped, a square
// load patch of side p at the centre of the top face, contact on the whole bottom face (z = 0).
// A contact-dominated body: the contact face is large against the volume, so the dual QP has
// many multipliers per unknown.
// Usage: gmsh -3 -setnumber h 0.05 -setnumber Lx 2 -setnumber Ly 2 -setnumber t 0.05 slab.geo -o slab.msh
// Physical groups: clamped (x = 0, x = Lx, y = 0, y = Ly), load_patch (centre of z = t), top (rest of
// z = t), contact (z = 0), body.
SetFactory("OpenCASCADE");
If (!Exists(h))
  h = 0.05;
EndIf
If (!Exists(Lx))
  Lx = 2;
EndIf
If (!Exists(Ly))
  Ly = 2;
EndIf
If (!Exists(t))
  t = 0.05;
EndIf
If (!Exists(p))
  p = 0.5;
EndIf
eps = 1e-6;
Box(1) = {0, 0, 0, Lx, Ly, t};
Rectangle(10) = {(Lx - p) / 2, (Ly - p) / 2, t, p, p};
v() = BooleanFragments{ Volume{1}; Delete; }{ Surface{10}; Delete; };
Mesh.MeshSizeMin = h;
Mesh.MeshSizeMax = h;
sides() = Surface In BoundingBox {-eps, -eps, -eps, eps, Ly + eps, t + eps};
sides() += Surface In BoundingBox {Lx - eps, -eps, -eps, Lx + eps, Ly + eps, t + eps};
sides() += Surface In BoundingBox {-eps, -eps, -eps, Lx + eps, eps, t + eps};
sides() += Surface In BoundingBox {-eps, Ly - eps, -eps, Lx + eps, Ly + eps, t + eps};
patch() = Surface In BoundingBox {(Lx - p) / 2 - eps, (Ly - p) / 2 - eps, t - eps, (Lx + p) / 2 + eps, (Ly + p) / 2 + eps, t + eps};
top() = Surface In BoundingBox {-eps, -eps, t - eps, Lx + eps, Ly + eps, t + eps};
top() -= {patch()};
contact() = Surface In BoundingBox {-eps, -eps, -eps, Lx + eps, Ly + eps, eps};
Physical Surface("clamped") = {sides()};
Physical Surface("load_patch") = {patch()};
Physical Surface("top") = {top()};
Physical Surface("contact") = {contact()};
Physical Volume("body") = {Volume{:}};
