SetFactory("OpenCASCADE");
Box(1) = {0, 0, 0, 1.9884994820991093, 1.6986781790419783, 0.04984426428696737};
eps = 0.0004984426428696737;
Mesh.MeshSizeMin = 0.04134831000910555; Mesh.MeshSizeMax = 0.04134831000910555;
bottom() = Surface In BoundingBox {-1e9, -1e9, -eps, 1e9, 1e9, eps};
top() = Surface In BoundingBox {-1e9, -1e9, 0.04984426428696737 - eps, 1e9, 1e9, 0.04984426428696737 + eps};
sides() = Surface{:};
sides() -= {bottom(), top()};
Physical Surface("contact") = {bottom()};
Physical Surface("top") = {top()};
Physical Surface("sides") = {sides()};
Physical Volume("body") = {Volume{:}};
Rotate {{-0.16501259467041557, 0.9386467557928448, 0.3028417267149699}, {0, 0, 0}, 0.3772529928441458} { Volume{:}; }
