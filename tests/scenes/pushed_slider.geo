// A block x in [0,A], y in [y0,B], z in [0,C] (y0 = 0: the half model, -B: the whole), a lower layer z < T
// under a core; its rear face (x = 0) is where a user pushes it.
SetFactory("OpenCASCADE");
If (!Exists(h)) h = 0.02; EndIf
If (!Exists(whole)) whole = 0; EndIf
A = 0.4; B = 0.1; C = 0.2; T = 0.05; eps = 1e-7;
y0 = 0; If (whole) y0 = -B; EndIf
Box(1) = {0, y0, 0, A, B - y0, T};
Box(2) = {0, y0, T, A, B - y0, C - T};
v() = BooleanFragments{ Volume{1}; Delete; }{ Volume{2}; Delete; };
Mesh.MeshSizeMax = h; Mesh.MeshSizeMin = h / 2;
Physical Volume("layer") = {Volume In BoundingBox {-eps, y0 - eps, -eps, A + eps, B + eps, T + eps}};
Physical Volume("core") = {Volume In BoundingBox {-eps, y0 - eps, T - eps, A + eps, B + eps, C + eps}};
Physical Surface("sole") = {Surface In BoundingBox {-eps, y0 - eps, -eps, A + eps, B + eps, eps}};
Physical Surface("top") = {Surface In BoundingBox {-eps, y0 - eps, C - eps, A + eps, B + eps, C + eps}};
Physical Surface("rear") = {Surface In BoundingBox {-eps, y0 - eps, -eps, eps, B + eps, C + eps}};
If (!whole)
  Physical Surface("sym_y") = {Surface In BoundingBox {-eps, -eps, -eps, A + eps, eps, C + eps}};
EndIf
