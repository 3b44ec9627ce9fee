SetFactory("OpenCASCADE");
Box(1) = {0, 0, 0, 0.8797636846412307, 0.8608564104614749, 0.014923147894556137};
eps = 0.00014923147894556137;
Mesh.MeshSizeMin = 0.015560085500351857; Mesh.MeshSizeMax = 0.015560085500351857;
bottom() = Surface In BoundingBox {-1e9, -1e9, -eps, 1e9, 1e9, eps};
top() = Surface In BoundingBox {-1e9, -1e9, 0.014923147894556137 - eps, 1e9, 1e9, 0.014923147894556137 + eps};
sides() = Surface{:};
sides() -= {bottom(), top()};
Physical Surface("contact") = {bottom()};
Physical Surface("top") = {top()};
Physical Surface("sides") = {sides()};
Physical Volume("body") = {Volume{:}};
Rotate {{-0.32843647443172846, 0.04933680950054301, -0.9432366413001373}, {0, 0, 0}, 0.21564299666857678} { Volume{:}; }
