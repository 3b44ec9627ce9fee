// A rubber block beside a steel block, fused (BooleanFragments: they share the nodes of their
// interface x = 0.05), both standing on the foundation: 0.1 x 0.1 x 0.05 m in all.
// Usage: gmsh -3 -setnumber h 0.006 bimaterial.geo -o bimaterial.msh
// Physical groups: contact (z = 0, Γc), top (z = 0.05), rubber (x < 0.05), steel (x > 0.05).
SetFactory("OpenCASCADE");
If (!Exists(h))
  h = 0.006;
EndIf
Box(1) = {0, 0, 0, 0.05, 0.1, 0.05};
Box(2) = {0.05, 0, 0, 0.05, 0.1, 0.05};
BooleanFragments{ Volume{1}; Delete; }{ Volume{2}; Delete; }
Mesh.CharacteristicLengthMax = h;
eps = 1e-6;
Physical Surface("contact") = Surface In BoundingBox {-eps, -eps, -eps, 0.1 + eps, 0.1 + eps, eps};
Physical Surface("top") = Surface In BoundingBox {-eps, -eps, 0.05 - eps, 0.1 + eps, 0.1 + eps, 0.05 + eps};
Physical Volume("rubber") = {1};
Physical Volume("steel") = {2};
