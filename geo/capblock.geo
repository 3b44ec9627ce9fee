// Quarter of a block whose underside is a shallow spherical cap, in two materials (OpenCASCADE).
// The block (0,a)x(0,a)x(0,H) is cut from below by a sphere of radius R touching z = 0 at the
// origin, so the underside Γc is curved and its height above the foundation is the initial gap
// d(x, y) = R - sqrt(R² - x² - y²) (about (x² + y²) / 2R). A layer of thickness t above the cap is
// a second volume ("layer", a softer material in the scene) under the "core".
// x = 0 and y = 0 are symmetry planes (rollers), the top is pushed down, the side x = a is pressed.
// Usage: gmsh -3 -setnumber h 0.05 capblock.geo -o capblock.msh
// Physical groups: sym_x (x = 0), sym_y (y = 0), top (z = H), side_x (x = a), contact (the cap),
// free (y = a), layer and core (volumes).
SetFactory("OpenCASCADE");
If (!Exists(h))
  h = 0.05;
EndIf
If (!Exists(R))
  R = 6.0;
EndIf
a = 0.5;
H = 0.4;
t = 0.1;
eps = 1e-6;
Box(1) = {0, 0, 0, a, a, H};
Sphere(2) = {0, 0, R, R};
BooleanIntersection(3) = { Volume{1}; Delete; }{ Volume{2}; Delete; };
// split at z = t into the layer below and the core above, conforming at the interface
Box(4) = {-1, -1, -1, a + 2, a + 2, 1 + t};
layer() = BooleanIntersection{ Volume{3}; }{ Volume{4}; };
core() = BooleanDifference{ Volume{3}; Delete; }{ Volume{4}; Delete; };
all() = BooleanFragments{ Volume{layer(), core()}; Delete; }{};
Mesh.MeshSizeMax = h;
Mesh.MeshSizeMin = h / 2;

// Classify by centre of mass: OpenCASCADE's bounding boxes of curved entities are loose.
layer() = {};
core() = {};
For i In {0 : #all() - 1}
  com() = CenterOfMass Volume{all(i)};
  If (com(2) < t)
    layer() += all(i);
  Else
    core() += all(i);
  EndIf
EndFor
sym_x() = Surface In BoundingBox {-eps, -eps, -eps, eps, a + eps, H + eps};
sym_y() = Surface In BoundingBox {-eps, -eps, -eps, a + eps, eps, H + eps};
top() = Surface In BoundingBox {-eps, -eps, H - eps, a + eps, a + eps, H + eps};
side_x() = Surface In BoundingBox {a - eps, -eps, -eps, a + eps, a + eps, H + eps};
free() = Surface In BoundingBox {-eps, a - eps, -eps, a + eps, a + eps, H + eps};
// the cap: the boundary surfaces whose centre of mass lies below the layer's mid-height and that
// are none of the planar faces
planar() = {sym_x(), sym_y(), side_x(), free()};
cap() = {};
bnd() = Abs(Boundary{ Volume{layer()}; });
For i In {0 : #bnd() - 1}
  com() = CenterOfMass Surface{bnd(i)};
  keep = com(2) < t / 2;
  For j In {0 : #planar() - 1}
    If (bnd(i) == planar(j))
      keep = 0;
    EndIf
  EndFor
  If (keep)
    cap() += bnd(i);
  EndIf
EndFor
Physical Surface("sym_x") = {sym_x()};
Physical Surface("sym_y") = {sym_y()};
Physical Surface("top") = {top()};
Physical Surface("side_x") = {side_x()};
Physical Surface("free") = {free()};
Physical Surface("contact") = {cap()};
Physical Volume("layer") = {layer()};
Physical Volume("core") = {core()};
