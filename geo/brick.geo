// The paper's brick (0,3) x (0,1) x (0,1) m, cut into 3n x n x n cubes, each split into
// tetrahedra by a structured extrusion (6 tets per cube; the paper's own 5-tet split comes
// from `contact3d mesh brick --n N`).  Usage: gmsh -3 -setnumber n 8 brick.geo -o brick.msh
// Physical groups: clamped (x=0, Γu), load_end (x=3), load_top (z=1), contact (z=0, Γc),
// free (y=0 and y=1), body.
If (!Exists(n))
  n = 4;
EndIf
Lx = 3; Ly = 1; Lz = 1;
eps = 1e-6;

Point(1) = {0, 0, 0, 1};
edge[] = Extrude {Lx, 0, 0} { Point{1}; Layers{3 * n}; };
face[] = Extrude {0, Ly, 0} { Line{edge[1]}; Layers{n}; };
vol[]  = Extrude {0, 0, Lz} { Surface{face[1]}; Layers{n}; };

Physical Surface("clamped")  = Surface In BoundingBox {-eps, -eps, -eps, eps, Ly + eps, Lz + eps};
Physical Surface("load_end") = Surface In BoundingBox {Lx - eps, -eps, -eps, Lx + eps, Ly + eps, Lz + eps};
Physical Surface("load_top") = Surface In BoundingBox {-eps, -eps, Lz - eps, Lx + eps, Ly + eps, Lz + eps};
Physical Surface("contact")  = Surface In BoundingBox {-eps, -eps, -eps, Lx + eps, Ly + eps, eps};
Physical Surface("free") = {Surface In BoundingBox {-eps, -eps, -eps, Lx + eps, eps, Lz + eps},
                            Surface In BoundingBox {-eps, Ly - eps, -eps, Lx + eps, Ly + eps, Lz + eps}};
Physical Volume("body") = {vol[1]};
