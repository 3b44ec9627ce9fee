// The paper's brick (0,3)x(0,1)x(0,1) m meshed unstructured (Delaunay, no transfinite),
// graded towards Γc: element size h at z = 0 growing linearly to 3h at z = 1.
// Usage: gmsh -3 -setnumber h 0.1 brick_unstructured.geo -o brick_u.msh
// Physical groups as brick.geo: clamped (x=0, Γu), load_end (x=3), load_top (z=1),
// contact (z=0, Γc), free (y=0 and y=1), body.
SetFactory("OpenCASCADE");
If (!Exists(h))
  h = 0.1;
EndIf
eps = 1e-6;
Box(1) = {0, 0, 0, 3, 1, 1};
Field[1] = MathEval;
Field[1].F = Sprintf("%g * (1 + 2 * z)", h);
Background Field = 1;
Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromPoints = 0;
Mesh.MeshSizeFromCurvature = 0;

Physical Surface("clamped") = Surface In BoundingBox {-eps, -eps, -eps, eps, 1 + eps, 1 + eps};
Physical Surface("load_end") = Surface In BoundingBox {3 - eps, -eps, -eps, 3 + eps, 1 + eps, 1 + eps};
Physical Surface("load_top") = Surface In BoundingBox {-eps, -eps, 1 - eps, 3 + eps, 1 + eps, 1 + eps};
Physical Surface("contact") = Surface In BoundingBox {-eps, -eps, -eps, 3 + eps, 1 + eps, eps};
Physical Surface("free") = {Surface In BoundingBox {-eps, -eps, -eps, 3 + eps, eps, 1 + eps},
                            Surface In BoundingBox {-eps, 1 - eps, -eps, 3 + eps, 1 + eps, 1 + eps}};
Physical Volume("body") = {1};
