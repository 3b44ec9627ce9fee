// A block 0.2 x 0.15 x 0.1 m: a soft layer (0 < z < 0.02) under a stiff core, turned ax° about x and ay°
// about y (tests/scenes/soft_layer_gap_under_pressure.toml: not turned).
SetFactory("OpenCASCADE");
If (!Exists(h)) h = 0.012; EndIf
If (!Exists(ax)) ax = 0; EndIf
If (!Exists(ay)) ay = 0; EndIf
a = 0.2; b = 0.15; c = 0.1; t = 0.02; e = 1e-5;
Box(1) = {-a/2, -b/2, 0, a, b, t};
Box(2) = {-a/2, -b/2, t, a, b, c - t};
v() = BooleanFragments{ Volume{1}; Delete; }{ Volume{2}; Delete; };
bot() = Surface In BoundingBox {-a, -b, -e, a, b, e};
top() = Surface In BoundingBox {-a, -b, c-e, a, b, c+e};
soft() = Volume In BoundingBox {-a, -b, -e, a, b, t+e};
all() = Volume{:};
hard() = all(); hard() -= {soft()};
If (ax != 0) Rotate {{1,0,0},{0,0,0}, ax*Pi/180} { Volume{:}; } EndIf
If (ay != 0) Rotate {{0,1,0},{0,0,0}, ay*Pi/180} { Volume{:}; } EndIf
Physical Surface("contact") = {bot()};
Physical Surface("top") = {top()};
Physical Volume("soft") = {soft()};
Physical Volume("hard") = {hard()};
Mesh.MeshSizeMax = h; Mesh.MeshSizeMin = h/2;
