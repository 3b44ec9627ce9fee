// Roller (OpenCASCADE): half of a cylinder, radius 0.5 m, length 0.8 m, axis along x at height R,
// lying on its curved side with the flat face up. Γc is the curved half: a face with an initial gap
// d = R − sqrt(R² − y²) that touches the plane along the line y = 0, so the contact zone is a strip
// that opens with the load (line contact, Hertz's 2D case). The flat top is moved by a prescribed
// displacement; the two half-disc ends are free.
// With h_line < h the mesh is graded towards the line of first touch (y = z = 0), as a user meshes a
// Hertz line contact: size h_line within `fine` of it, growing linearly (slope `growth`) up to h.
// Usage: gmsh -3 -setnumber h 0.04 roller.geo -o roller.msh
// Physical groups: top (z = R), ends (x = 0 and x = L), contact (the curved half), body.
SetFactory("OpenCASCADE");
If (!Exists(h))
  h = 0.04;
EndIf
If (!Exists(h_line)) h_line = h; EndIf
If (!Exists(fine)) fine = 0.01; EndIf
If (!Exists(growth)) growth = 0.3; EndIf
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
If (h_line < h)
  Field[1] = MathEval;
  Field[1].F = "Sqrt(y * y + z * z)";  // distance to the line of first touch
  Field[2] = Threshold;
  Field[2].InField = 1;
  Field[2].SizeMin = h_line;
  Field[2].SizeMax = h;
  Field[2].DistMin = fine;
  Field[2].DistMax = fine + (h - h_line) / growth;
  Background Field = 2;
  Mesh.MeshSizeExtendFromBoundary = 0;
  Mesh.MeshSizeFromPoints = 0;
  Mesh.MeshSizeFromCurvature = 0;
  Mesh.MeshSizeMin = h_line;
EndIf
