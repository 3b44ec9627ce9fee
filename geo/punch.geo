// Punch (OpenCASCADE): a block (0,2)x(0,1)x(0.3,1) m standing on a narrow foot
// (0.6,1.6)x(0.25,0.75)x(0,0.3) m. Γc is only the foot's sole; the block's underside
// (z = 0.3) is free. Pressure concentrates at the sole's edges (punch singularity).
// Usage: gmsh -3 -setnumber h 0.08 punch.geo -o punch.msh
// Physical groups: clamped (x=0, Γu), load_top (z=1), load_end (x=2), contact (z=0, Γc),
// free (everything else), body.
SetFactory("OpenCASCADE");
If (!Exists(h))
  h = 0.08;
EndIf
eps = 1e-6;
Box(1) = {0, 0, 0.3, 2, 1, 0.7};
Box(2) = {0.6, 0.25, 0, 1.0, 0.5, 0.3};
v() = BooleanUnion{ Volume{1}; Delete; }{ Volume{2}; Delete; };
Mesh.MeshSizeMin = h;
Mesh.MeshSizeMax = 2 * h;
// finer near the sole: h at z = 0, 2h from z = 0.6 up
Field[1] = MathEval;
Field[1].F = Sprintf("%g * (1 + Min(z, 0.6) / 0.6)", h);
Background Field = 1;
Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromPoints = 0;
Mesh.MeshSizeFromCurvature = 0;

clamped() = Surface In BoundingBox {-eps, -eps, 0.3 - eps, eps, 1 + eps, 1 + eps};
top() = Surface In BoundingBox {-eps, -eps, 1 - eps, 2 + eps, 1 + eps, 1 + eps};
tip() = Surface In BoundingBox {2 - eps, -eps, 0.3 - eps, 2 + eps, 1 + eps, 1 + eps};
contact() = Surface In BoundingBox {-eps, -eps, -eps, 2 + eps, 1 + eps, eps};
free() = Surface{:};
free() -= {clamped(), top(), tip(), contact()};
Physical Surface("clamped") = {clamped()};
Physical Surface("load_top") = {top()};
Physical Surface("load_end") = {tip()};
Physical Surface("contact") = {contact()};
Physical Surface("free") = {free()};
Physical Volume("body") = {v()};
