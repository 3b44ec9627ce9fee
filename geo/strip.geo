// A long thin strip L x W x t (m) lying on the foundation: the end x = 0 clamped, a load patch of length p
// on the top at the far end. One element through the thickness at the default h: a contact-dominated,
// slender body whose dual operator Q is ill-conditioned (cond(Q) 1e9 - 1e10). Groups: clamped,
// load_patch, top, contact, body.
SetFactory("OpenCASCADE");
DefineConstant[ h = 0.01, L = 1, W = 0.1, t = 0.005, p = 0.1 ];
eps = 1e-7;
Box(1) = {0, 0, 0, L, W, t};
Rectangle(10) = {L - p, 0, t, p, W};
v() = BooleanFragments{ Volume{1}; Delete; }{ Surface{10}; Delete; };
Mesh.MeshSizeMax = h;
Mesh.MeshSizeMin = h;
end() = Surface In BoundingBox{-eps, -eps, -eps, eps, W + eps, t + eps};
patch() = Surface In BoundingBox{L - p - eps, -eps, t - eps, L + eps, W + eps, t + eps};
top() = Surface In BoundingBox{-eps, -eps, t - eps, L + eps, W + eps, t + eps};
top() -= {patch()};
bottom() = Surface In BoundingBox{-eps, -eps, -eps, L + eps, W + eps, eps};
Physical Surface("clamped") = {end()};
Physical Surface("load_patch") = {patch()};
Physical Surface("top") = {top()};
Physical Surface("contact") = {bottom()};
Physical Volume("body") = {Volume{:}};
