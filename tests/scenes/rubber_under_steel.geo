// Rubber-backed steel shim 100 x 40 mm: 3 mm rubber (z in [0, 3 mm]) bonded under 1.5 mm steel.
SetFactory("OpenCASCADE");
If (!Exists(h))
  h = 0.002;
EndIf
Lx = 0.1; Ly = 0.04; tr = 0.003; ts = 0.0015; eps = 1e-6;
Box(1) = {0, 0, 0, Lx, Ly, tr};
Box(2) = {0, 0, tr, Lx, Ly, ts};
BooleanFragments{ Volume{1}; Delete; }{ Volume{2}; Delete; }
Mesh.MeshSizeMax = h;
Physical Surface("contact") = Surface In BoundingBox{-eps, -eps, -eps, Lx+eps, Ly+eps, eps};
Physical Surface("top") = Surface In BoundingBox{-eps, -eps, tr+ts-eps, Lx+eps, Ly+eps, tr+ts+eps};
Physical Volume("rubber") = {1};
Physical Volume("steel") = {2};
