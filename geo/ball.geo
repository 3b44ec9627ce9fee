// Ball (OpenCASCADE): a sphere of radius R resting on its pole on the plane z = 0, nothing holding
// it but the contact. The mesh is graded towards the pole, as a user meshes a Hertz contact: size
// h_pole within `fine` of it, growing linearly (slope `growth`) up to h. The lower cap (z <= 0.6 R,
// a graph over the plane) is the contact group; the rest of the surface is `upper`.
// Usage: gmsh -3 -setnumber h_pole 0.0008 ball.geo -o ball.msh
// Physical groups: contact (the lower cap), upper (the rest of the sphere), body.
SetFactory("OpenCASCADE");
If (!Exists(R)) R = 0.5; EndIf
If (!Exists(h)) h = 0.04; EndIf
If (!Exists(h_pole)) h_pole = 0.0008; EndIf
If (!Exists(fine)) fine = 0.01; EndIf
If (!Exists(growth)) growth = 0.3; EndIf
zc = 0.6 * R;  // height of the cut between the contact cap and the rest
eps = 1e-6 * R;
Sphere(1) = {0, 0, R, R};
Box(2) = {-2 * R, -2 * R, -2 * R, 4 * R, 4 * R, 2 * R + zc};
v() = BooleanFragments{ Volume{1}; Delete; }{ Volume{2}; Delete; };
Recursive Delete { Volume{v(#v() - 1)}; }
low() = Surface In BoundingBox {-R - eps, -R - eps, -eps, R + eps, R + eps, zc + eps};
cut() = Surface In BoundingBox {-R - eps, -R - eps, zc - eps, R + eps, R + eps, zc + eps};
low() -= {cut()};
Physical Surface("contact") = {low()};
rest() = Surface{:};
rest() -= {low(), cut()};
Physical Surface("upper") = {rest()};
Physical Volume("body") = {Volume{:}};

pole() = Point In BoundingBox {-eps, -eps, -eps, eps, eps, eps};
Field[1] = Distance;
Field[1].PointsList = {pole()};
Field[2] = Threshold;
Field[2].InField = 1;
Field[2].SizeMin = h_pole;
Field[2].SizeMax = h;
Field[2].DistMin = fine;
Field[2].DistMax = fine + (h - h_pole) / growth;
Background Field = 2;
Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromPoints = 0;
Mesh.MeshSizeFromCurvature = 0;
Mesh.MeshSizeMax = h;
