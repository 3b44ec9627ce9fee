// Puck (OpenCASCADE): a cylinder of radius 0.5 m and height 0.2 m standing on its face. The top
// face is held (Γu); the body's weight (a body force) presses the sole onto the plane and a
// traction on the +x half of the mantle pushes it sideways. Γc (z = 0) is a disc: the rectangle
// partition is clipped along a circle everywhere on its rim.
// Usage: gmsh -3 -setnumber h 0.05 puck.geo -o puck.msh
// Physical groups: clamped (z = 0.2), load_side (mantle, x > 0), contact (z = 0), free (mantle,
// x < 0), body.
SetFactory("OpenCASCADE");
If (!Exists(h))
  h = 0.05;
EndIf
R = 0.5; H = 0.2; eps = 1e-6;
Cylinder(1) = {0, 0, 0, 0, 0, H, R};
// Split the mantle at x = 0 so that half of it can be loaded.
Box(2) = {0, -R - 1, -1, R + 1, 2 * R + 2, H + 2};
v() = BooleanFragments{ Volume{1}; Delete; }{ Volume{2}; Delete; };
Recursive Delete { Volume{v(#v() - 1)}; }
Mesh.MeshSizeMin = h;
Mesh.MeshSizeMax = h;
top() = Surface In BoundingBox {-R - eps, -R - eps, H - eps, R + eps, R + eps, H + eps};
contact() = Surface In BoundingBox {-R - eps, -R - eps, -eps, R + eps, R + eps, eps};
side() = Surface In BoundingBox {-eps, -R - eps, -eps, R + eps, R + eps, H + eps};
side() -= {top(), contact()};
// The cut at x = 0 stays inside the body as a face of both halves; the box above holds it too.
cut() = Surface In BoundingBox {-eps, -R - eps, -eps, eps, R + eps, H + eps};
side() -= {cut()};
free() = Surface{:};
free() -= {top(), contact(), side(), cut()};
Physical Surface("clamped") = {top()};
Physical Surface("load_side") = {side()};
Physical Surface("contact") = {contact()};
Physical Surface("free") = {free()};
Physical Volume("body") = {Volume{:}};
