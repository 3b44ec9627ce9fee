// Roller (OpenCASCADE): half of a cylinder, radius 0.5 m, length 0.8 m, axis along x at height R,
// lying on its curved side with the flat face up. Γc is the curved half: a face with an initial gap
// d = R − sqrt(R² − y²) that touches the plane along the line y = 0, so the contact zone is a strip
// that opens with the load (line contact, Hertz's 2D case). The flat top is moved by a prescribed
// displacement; the two half-disc ends are free.
// Usage: gmsh -3 -setnumber h 0.04 roller.geo -o roller.msh
// Physical groups: top (z = R), ends (x = 0 and x = L), contact (the curved half), body.
SetFactory("OpenCASCADE");
If (!Exists(h))
  h = 0.04;
EndIf
R = 0.5; L = 0.8; eps = 1e-6;
Cylinder(1) = {0, 0, R, L, 0, 0, R};
Box(2) = {-0.1, -1, R, L + 0.2, 2, 1};
BooleanDifference(3) = { Volume{1}; Delete; }{ Volume{2}; Delete; };
Mesh.MeshSizeMin = h;
Mesh.MeshSizeMax = h;
top() = Surface In BoundingBox {-eps, -R - eps, R - eps, L + eps, R + eps, R + eps};
ends() = Surface In BoundingBox {-eps, -R - eps, -eps, eps, R + eps, R + eps};
ends() += Surface In BoundingBox {L - eps, -R - eps, -eps, L + eps, R + eps, R + eps};
contact() = Surface{:};
contact() -= {top(), ends()};
Physical Surface("top") = {top()};
Physical Surface("ends") = {ends()};
Physical Surface("contact") = {contact()};
Physical Volume("body") = {Volume{:}};
