// Hexagonal prism with an off-centre vertical hole (OpenCASCADE), standing on its hexagonal face:
// circumradius 0.5 m, height 0.3 m, hole radius 0.12 m at (0.1, 0.05). An unstructured body the
// tests and the robustness table use: Γc (z = 0) is a hexagon with a hole, so the rectangle
// partition is clipped on slanted edges and around a circle.
// Usage: gmsh -3 -setnumber h 0.06 hexprism.geo -o hexprism.msh
// Physical groups: clamped (the flank facing −x), load_top (z = 0.3), load_side (the flank facing
// +x), contact (z = 0), free (the other flanks and the hole), body.
SetFactory("OpenCASCADE");
If (!Exists(h))
  h = 0.06;
EndIf
R = 0.5; H = 0.3; eps = 1e-6;
For k In {0:5}
  Point(k + 1) = {R * Cos(k * Pi / 3 + Pi / 6), R * Sin(k * Pi / 3 + Pi / 6), 0};
EndFor
For k In {0:5}
  Line(k + 1) = {k + 1, (k + 1) % 6 + 1};
EndFor
Curve Loop(1) = {1, 2, 3, 4, 5, 6};
Plane Surface(1) = {1};
e() = Extrude {0, 0, H} { Surface{1}; };
Cylinder(10) = {0.1, 0.05, -0.1, 0, 0, H + 0.2, 0.12};
v() = BooleanDifference{ Volume{e(1)}; Delete; }{ Volume{10}; Delete; };
Mesh.MeshSizeMin = h;
Mesh.MeshSizeMax = h;
c = R * Cos(Pi / 6);  // apothem: flanks facing ±x lie at x = ±c
clamped() = Surface In BoundingBox {-c - eps, -R - eps, -eps, -c + eps, R + eps, H + eps};
side() = Surface In BoundingBox {c - eps, -R - eps, -eps, c + eps, R + eps, H + eps};
top() = Surface In BoundingBox {-R - eps, -R - eps, H - eps, R + eps, R + eps, H + eps};
contact() = Surface In BoundingBox {-R - eps, -R - eps, -eps, R + eps, R + eps, eps};
free() = Surface{:};
free() -= {clamped(), side(), top(), contact()};
Physical Surface("clamped") = {clamped()};
Physical Surface("load_top") = {top()};
Physical Surface("load_side") = {side()};
Physical Surface("contact") = {contact()};
Physical Surface("free") = {free()};
Physical Volume("body") = {v()};
