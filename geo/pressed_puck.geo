// Pressed puck (OpenCASCADE): a steel disc of radius 50 mm and height 40 mm standing on its face,
// its top face moved down and sideways (Γu), so that the sole is pressed flat and mostly sticks.
// Usage: gmsh -3 -setnumber h 0.005 pressed_puck.geo -o pressed_puck.msh
// Physical groups: top (z = H), contact (z = 0), body.
SetFactory("OpenCASCADE");
If (!Exists(h))
  h = 0.012;
EndIf
r = 0.05; H = 0.04; eps = 1e-6;
Cylinder(1) = {0, 0, 0, 0, 0, H, r};
Mesh.MeshSizeMax = h;
Physical Surface("contact") = Surface In BoundingBox {-r - eps, -r - eps, -eps, r + eps, r + eps, eps};
Physical Surface("top") = Surface In BoundingBox {-r - eps, -r - eps, H - eps, r + eps, r + eps, H + eps};
Physical Volume("body") = {1};
