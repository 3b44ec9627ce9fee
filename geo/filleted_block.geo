// A block 0.2 x 0.1 x 0.1 m whose bottom edges are rounded (fillets of radius r): its flat sole lies
// on the foundation, the fillets rise from the sole's edge as (s^2 / 2r) at a distance s from it.
// Usage: gmsh -3 -setnumber h 0.008 filleted_block.geo -o filleted_block.msh
// Physical groups: contact (the sole and the fillets, Γc), top (z = 0.1), body.
SetFactory("OpenCASCADE");
If (!Exists(h))
  h = 0.008;
EndIf
If (!Exists(r))
  r = 0.02;
EndIf
Box(1) = {0, 0, 0, 0.2, 0.1, 0.1};
bottom_edges() = Abs(Boundary{ Surface{5}; });
rounded() = Fillet{1}{bottom_edges()}{r};
Mesh.CharacteristicLengthMax = h;
eps = 1e-6;
Physical Surface("contact") = Surface In BoundingBox {-eps, -eps, -eps, 0.2 + eps, 0.1 + eps, r + eps};
Physical Surface("top") = Surface In BoundingBox {-eps, -eps, 0.1 - eps, 0.2 + eps, 0.1 + eps, 0.1 + eps};
Physical Volume("body") = {rounded()};
