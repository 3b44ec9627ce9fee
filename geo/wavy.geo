// Block on a wavy sole (built-in kernel): Lx x Ly x H, its contact face z = a (1 - cos(2 pi x / lambda))
// a cylindrical wave along x touching the foundation along the troughs (x = 0, lambda, 2 lambda, ...)
// and lifted by up to 2a between them. Pressed down, it touches in several strips separated by gaps,
// which grow as the load rises: a curved contact face with an initial gap and more than one contact zone.
// Usage: gmsh -3 -setnumber h 0.02 wavy.geo -o wavy.msh
// Physical groups: contact (the sole), top (z = H), sym_x (x = 0), end_x (x = Lx), sym_y (y = 0),
// end_y (y = Ly), body.
DefineConstant[ h = 0.02, Lx = 0.4, Ly = 0.2, H = 0.1, a = 2e-4, lambda = 0.2, points = 81 ];
For i In {0 : points - 1}
  x = Lx * i / (points - 1);
  Point(i + 1) = {x, 0, a * (1 - Cos(2 * Pi * x / lambda)), h};
EndFor
Spline(1) = {1 : points};
Point(points + 1) = {Lx, 0, H, h};
Point(points + 2) = {0, 0, H, h};
Line(2) = {points, points + 1};
Line(3) = {points + 1, points + 2};
Line(4) = {points + 2, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
extruded[] = Extrude {0, Ly, 0} { Surface{1}; };
// extruded[]: the far face (y = Ly), the volume, then the faces swept by curves 1, 2, 3, 4.
Physical Surface("contact") = {extruded[2]};
Physical Surface("end_x") = {extruded[3]};
Physical Surface("top") = {extruded[4]};
Physical Surface("sym_x") = {extruded[5]};
Physical Surface("sym_y") = {1};
Physical Surface("end_y") = {extruded[0]};
Physical Volume("body") = {extruded[1]};
