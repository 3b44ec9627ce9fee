// Two machine pads meshed as one file (OpenCASCADE): a block 1 x 0.5 x 0.3 m and a lower one
// 0.6 x 0.5 x 0.2 m beside it, 0.05 m apart: two volumes that share no node, so the mesh has two
// disconnected parts. Both rest on the foundation z = 0.
// Usage: gmsh -3 -setnumber h 0.08 pads.geo -o pads.msh
// Physical groups: contact (both soles), top (both tops), body.
SetFactory("OpenCASCADE");
DefineConstant[ h = 0.08, gap = 0.05 ];
Box(1) = {0, 0, 0, 1, 0.5, 0.3};
Box(2) = {1 + gap, 0, 0, 0.6, 0.5, 0.2};
Mesh.MeshSizeMin = h; Mesh.MeshSizeMax = h;
eps = 1e-6;
Physical Surface("contact") = Surface In BoundingBox {-eps, -eps, -eps, 2, 1, eps};
top() = Surface In BoundingBox {-eps, -eps, 0.3 - eps, 2, 1, 0.3 + eps};
top() += Surface In BoundingBox {1 + gap - eps, -eps, 0.2 - eps, 2, 1, 0.2 + eps};
Physical Surface("top") = {top()};
Physical Volume("body") = {1, 2};
