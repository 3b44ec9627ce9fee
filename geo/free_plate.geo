// Steel plate 1 x 1 x T lying free on the ground (no clamp), a 0.1 x 0.1 load patch in the middle
// of its top. Groups: "bottom" (the contact face), "patch", "body".
SetFactory("OpenCASCADE");
If (!Exists(h)) h = 0.02; EndIf
If (!Exists(T)) T = 0.02; EndIf
Box(1) = {-0.5, -0.5, 0, 1, 1, T};
Rectangle(10) = {-0.05, -0.05, T, 0.1, 0.1};
BooleanFragments{ Volume{1}; Delete; }{ Surface{10}; Delete; }
Mesh.MeshSizeMax = h;
eps = 1e-6;
Physical Surface("bottom") = Surface In BoundingBox{-0.5 - eps, -0.5 - eps, -eps, 0.5 + eps, 0.5 + eps, eps};
Physical Surface("patch") = Surface In BoundingBox{-0.05 - eps, -0.05 - eps, T - eps, 0.05 + eps, 0.05 + eps, T + eps};
Physical Volume("body") = Volume{:};
