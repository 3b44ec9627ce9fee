// T-shaped steel plate, 6 mm thick, meshed anisotropically: the 2D T meshed at in-plane size h and
// extruded in nl layers (tets), so elements are h wide and t/nl thick.
// Bar [-0.15,0.15]x[0.24,0.30], stem [-0.03,0.03]x[0,0.24].
SetFactory("OpenCASCADE");
If (!Exists(h))
  h = 0.009;
EndIf
If (!Exists(nl))
  nl = 2;
EndIf
t = 0.006; eps = 1e-6;
Rectangle(1) = {-0.15, 0.24, 0, 0.30, 0.06};
Rectangle(2) = {-0.03, 0, 0, 0.06, 0.24};
BooleanUnion(3) = { Surface{1}; Delete; }{ Surface{2}; Delete; };
Mesh.MeshSizeMax = h;
Mesh.MeshSizeMin = h;
ext[] = Extrude {0, 0, t} { Surface{3}; Layers{nl}; };
Physical Surface("contact") = Surface In BoundingBox{-1, -1, -eps, 1, 1, eps};
Physical Surface("top") = Surface In BoundingBox{-1, -1, t-eps, 1, 1, t+eps};
Physical Surface("stem_end") = Surface In BoundingBox{-0.03-eps, -eps, -eps, 0.03+eps, eps, t+eps};
Physical Surface("bar_ends") = Surface In BoundingBox{-0.15-eps, 0.24-eps, -eps, -0.15+eps, 0.3+eps, t+eps};
Physical Surface("bar_ends") += Surface In BoundingBox{0.15-eps, 0.24-eps, -eps, 0.15+eps, 0.3+eps, t+eps};
Physical Volume("body") = {ext[1]};
