// A quarter of an elastic hemisphere of radius R resting on its pole on the plane z = 0 (x, y >= 0,
// 0 <= z <= R), for the Hertz validation (tests/hertz_hemisphere.py). The volume is split at the
// height zc of the spherical cap of radius cap·R so that the cap alone is the contact group (the
// rest of the sphere rises too steeply to be a graph over the plane). The mesh is refined at the
// pole: size h_pole within fine·R of it, then growing linearly (slope `growth`) up to h_far.
// Physical groups: contact (the cap), sym_x (x = 0), sym_y (y = 0), top (z = R), body.
// Usage: gmsh -3 -setnumber h_pole 0.01 hertz_quarter.geo -o hertz.msh
SetFactory("OpenCASCADE");
If (!Exists(R)) R = 1; EndIf
If (!Exists(cap)) cap = 0.3; EndIf
If (!Exists(h_pole)) h_pole = 0.01; EndIf
If (!Exists(h_far)) h_far = 0.15; EndIf
If (!Exists(growth)) growth = 0.3; EndIf
If (!Exists(fine)) fine = 0.35; EndIf
zc = R - Sqrt(R * R - cap * cap * R * R);
eps = 1e-5 * R;  // gmsh pads bounding boxes by ~1e-7

Sphere(1) = {0, 0, R, R};
Box(2) = {0, 0, 0, R, R, R};
quarter() = BooleanIntersection{ Volume{1}; Delete; }{ Volume{2}; Delete; };
Box(3) = {0, 0, 0, R, R, zc};
pieces() = BooleanFragments{ Volume{quarter()}; Delete; }{ Volume{3}; Delete; };
// Keep the pieces inside the sphere: the box's corner outside it is dropped.
For i In {0 : #pieces() - 1}
  bb() = BoundingBox Volume{pieces(i)};
  If (bb(2) > -eps && bb(0) < eps && bb(1) < eps && bb(5) < zc + eps && bb(3) > cap * R + 0.01 * R)
    Recursive Delete { Volume{pieces(i)}; }
  EndIf
EndFor

contact() = {};
symx() = {};
symy() = {};
top() = {};
all_surfaces() = Surface{:};
For i In {0 : #all_surfaces() - 1}
  s = all_surfaces(i);
  bb() = BoundingBox Surface{s};
  If (bb(3) < eps)
    symx() += s;
  ElseIf (bb(4) < eps)
    symy() += s;
  ElseIf (bb(2) > R - eps)
    top() += s;
  ElseIf (bb(2) < eps && bb(5) < zc + eps)
    contact() += s;
  EndIf
EndFor
Physical Surface("contact") = {contact()};
Physical Surface("sym_x") = {symx()};
Physical Surface("sym_y") = {symy()};
Physical Surface("top") = {top()};
Physical Volume("body") = {Volume{:}};

pole() = Point In BoundingBox {-eps, -eps, -eps, eps, eps, eps};
Field[1] = Distance;
Field[1].PointsList = {pole()};
Field[2] = Threshold;
Field[2].InField = 1;
Field[2].SizeMin = h_pole;
Field[2].SizeMax = h_far;
Field[2].DistMin = fine * R;
Field[2].DistMax = fine * R + (h_far - h_pole) / growth;
Background Field = 2;
Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromPoints = 0;
Mesh.MeshSizeFromCurvature = 0;
Mesh.MeshSizeMax = h_far;
