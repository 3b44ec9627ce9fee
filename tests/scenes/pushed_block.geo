// A 0.2 x 0.2 x 0.1 m block (tests/scenes/block_pushed_at_friction_limit.toml, block_above_plane_tresca.toml).
SetFactory("OpenCASCADE");
If (!Exists(h)) h = 0.015; EndIf
a = 0.2; b = 0.2; c = 0.1; e = 1e-6;
Box(1) = {0, 0, 0, a, b, c};
Physical Surface("contact") = Surface In BoundingBox {-e, -e, -e, a+e, b+e, e};
Physical Surface("top") = Surface In BoundingBox {-e, -e, c-e, a+e, b+e, c+e};
Physical Surface("side") = Surface In BoundingBox {a-e, -e, -e, a+e, b+e, c+e};
Physical Volume("body") = {1};
Mesh.MeshSizeMax = h; Mesh.MeshSizeMin = h/2;
