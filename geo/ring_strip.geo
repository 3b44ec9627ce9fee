// A quarter of an O-ring's lower half (ring radius R, cord radius r) lying on the foundation z = 0:
// pressed down, it touches along a quarter circle, a curved line contact a few tenths of a millimetre
// wide. Meshed finer near the contact line (hl) than elsewhere (h).
// Physical groups: top (the flat cut at z = r, pressed), symx (x = 0), symy (y = 0), lower (the
// curved face below z = zc, the contact group), body.
SetFactory("OpenCASCADE");
If (!Exists(h)) h = 0.004; EndIf
If (!Exists(hl)) hl = 0.0005; EndIf
R = 0.05; r = 0.01; zc = 0.004;
Torus(1) = {0, 0, r, R, r, Pi/2};
Box(2) = {-0.1, -0.1, r, 0.2, 0.2, 0.1};
half() = BooleanDifference{ Volume{1}; Delete; }{ Volume{2}; Delete; };
Box(3) = {-0.1, -0.1, -0.01, 0.2, 0.2, 0.01 + zc};
parts() = BooleanFragments{ Volume{half()}; Delete; }{ Volume{3}; Delete; };
For i In {0 : #parts() - 1}  // the box's part below the plane goes
  box() = BoundingBox Volume{parts(i)};
  If (box(0) < -0.05) Recursive Delete { Volume{parts(i)}; } EndIf
EndFor
e = 1e-6;
Physical Surface("top") = Surface In BoundingBox{-0.1, -0.1, r - e, 0.1, 0.1, r + e};
Physical Surface("symx") = Surface In BoundingBox{-e, -0.1, -e, e, 0.1, r + e};
Physical Surface("symy") = Surface In BoundingBox{-0.1, -e, -e, 0.1, e, r + e};
// The curved face below zc: the surface reaching down to the plane that is not a symmetry plane's strip
// (OpenCASCADE's boxes of curved faces are loose, so it is picked by its lowest point and its extent).
lower() = {};
faces() = Surface{:};
For i In {0 : #faces() - 1}
  box() = BoundingBox Surface{faces(i)};
  If (box(2) < e && box(3) - box(0) > r && box(4) - box(1) > r) lower() += faces(i); EndIf
EndFor
Physical Surface("lower") = {lower()};
Physical Volume("body") = Volume{:};
Field[1] = MathEval; Field[1].F = Sprintf("Sqrt((Sqrt(x*x+y*y)-%g)^2+z*z)", R);
Field[2] = Threshold; Field[2].InField = 1; Field[2].SizeMin = hl; Field[2].SizeMax = h;
Field[2].DistMin = 0.002; Field[2].DistMax = 0.008;
Background Field = 2;
Mesh.MeshSizeExtendFromBoundary = 0; Mesh.MeshSizeFromPoints = 0; Mesh.MeshSizeFromCurvature = 0;
Mesh.MeshSizeMax = h;
