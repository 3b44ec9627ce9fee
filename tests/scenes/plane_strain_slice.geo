// A plane-strain slice (2 mm) of a half cylinder (x >= 0, R = 50 mm, axis along y at z = R) lying on its
// side, split at z = R into a lower and an upper volume; meshed finer towards the contact line (h_line).
SetFactory("OpenCASCADE");
If (!Exists(h)) h = 0.005; EndIf
If (!Exists(h_line)) h_line = 0.00025; EndIf
If (!Exists(fine)) fine = 0.004; EndIf
R = 0.05; L = 0.002; eps = 1e-7;
Cylinder(1) = {0, 0, R, 0, L, 0, R};
Box(2) = {-1, -1, -1, 1, 2, 3};
BooleanDifference(3) = { Volume{1}; Delete; }{ Volume{2}; Delete; };
Box(4) = {-1, -1, R, 2, 2, 2};
up() = BooleanIntersection{ Volume{3}; }{ Volume{4}; };
lo() = BooleanDifference{ Volume{3}; Delete; }{ Volume{4}; Delete; };
all() = BooleanFragments{ Volume{up(), lo()}; Delete; }{};
up() = {}; lo() = {};
For i In {0 : #all() - 1}
  com() = CenterOfMass Volume{all(i)};
  If (com(2) > R) up() += all(i); Else lo() += all(i); EndIf
EndFor
symx() = {}; ends() = {};
ba() = Abs(Boundary{ Volume{all()}; });
For i In {0 : #ba() - 1}
  com() = CenterOfMass Surface{ba(i)};
  If (Fabs(com(0)) < 1e-6) symx() += ba(i); EndIf
  If (Fabs(com(1)) < 1e-9 || Fabs(com(1) - L) < 1e-9) ends() += ba(i); EndIf
EndFor
bl() = Abs(Boundary{ Volume{lo()}; });
bu() = Abs(Boundary{ Volume{up()}; });
cont() = {}; pres() = {};
For i In {0 : #bl() - 1}
  com() = CenterOfMass Surface{bl(i)};
  If (com(0) > 1e-3 && com(1) > eps && com(1) < L - eps && com(2) < R - 1e-3) cont() += bl(i); EndIf
EndFor
For i In {0 : #bu() - 1}
  com() = CenterOfMass Surface{bu(i)};
  If (com(0) > 1e-3 && com(1) > eps && com(1) < L - eps && com(2) > R + 1e-3) pres() += bu(i); EndIf
EndFor
Physical Surface("sym_x") = {symx()};
Physical Surface("ends") = {ends()};
Physical Surface("contact") = {cont()};
Physical Surface("top_curved") = {pres()};
Physical Volume("lower") = {lo()};
Physical Volume("upper") = {up()};
Field[1] = MathEval;
Field[1].F = "Sqrt(x * x + z * z)";
Field[2] = Threshold;
Field[2].InField = 1;
Field[2].SizeMin = h_line;
Field[2].SizeMax = h;
Field[2].DistMin = fine;
Field[2].DistMax = fine + (h - h_line) / 0.3;
Background Field = 2;
Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromPoints = 0;
Mesh.MeshSizeFromCurvature = 0;
Mesh.MeshSizeMin = h_line;
Mesh.MeshSizeMax = h;
