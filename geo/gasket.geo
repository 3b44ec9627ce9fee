// A quarter of a flat annular gasket (inner radius Ri, outer Ro, thickness t) lying on its
// foundation: the bottom face is the whole contact face, the top is pressed, and the two cut
// faces x = 0 and y = 0 are symmetry planes. Physical groups: contact, top, sym_x, sym_y, body.
SetFactory("OpenCASCADE");
DefineConstant[ h = 0.004, Ro = 0.1, Ri = 0.06, t = 0.005 ];
Cylinder(1) = {0, 0, 0, 0, 0, t, Ro, Pi / 2};
Cylinder(2) = {0, 0, 0, 0, 0, t, Ri, Pi / 2};
BooleanDifference(3) = { Volume{1}; Delete; }{ Volume{2}; Delete; };
Mesh.CharacteristicLengthMax = h;
eps = 1e-3 * h;
Physical Surface("contact") = Surface In BoundingBox{-eps, -eps, -eps, Ro + eps, Ro + eps, eps};
Physical Surface("top") = Surface In BoundingBox{-eps, -eps, t - eps, Ro + eps, Ro + eps, t + eps};
Physical Surface("sym_x") = Surface In BoundingBox{-eps, -eps, -eps, eps, Ro + eps, t + eps};
Physical Surface("sym_y") = Surface In BoundingBox{-eps, -eps, -eps, Ro + eps, eps, t + eps};
Physical Volume("body") = {3};
