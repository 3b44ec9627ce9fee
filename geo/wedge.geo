// Wedge (built-in kernel): a prism over the trapezoid (0,0) (2,0.25) (2,0.75) (0,1) (m) whose
// top slopes from z = 1 at x = 0 down to z = 0.4 at x = 2. Γc (z = 0) is a trapezoid, so the
// rectangle grid is cut by the two slanted edges (clipped and merged boundary cells).
// Usage: gmsh -3 -setnumber h 0.1 wedge.geo -o wedge.msh
// Physical groups: clamped (x=0, Γu), load_top (sloped top), load_end (x=2),
// contact (z=0, Γc), free (the two slanted sides), body.
If (!Exists(h))
  h = 0.1;
EndIf
eps = 1e-6;
Point(1) = {0, 0, 0, h};    Point(2) = {2, 0.25, 0, h};
Point(3) = {2, 0.75, 0, h}; Point(4) = {0, 1, 0, h};
Point(5) = {0, 0, 1, h};    Point(6) = {2, 0.25, 0.4, h};
Point(7) = {2, 0.75, 0.4, h}; Point(8) = {0, 1, 1, h};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1};
Line(5) = {5, 6}; Line(6) = {6, 7}; Line(7) = {7, 8}; Line(8) = {8, 5};
Line(9) = {1, 5}; Line(10) = {2, 6}; Line(11) = {3, 7}; Line(12) = {4, 8};
Curve Loop(1) = {1, 2, 3, 4};      Plane Surface(1) = {1};   // bottom
Curve Loop(2) = {5, 6, 7, 8};      Plane Surface(2) = {2};   // sloped top
Curve Loop(3) = {1, 10, -5, -9};   Plane Surface(3) = {3};   // side y ~ 0
Curve Loop(4) = {2, 11, -6, -10};  Plane Surface(4) = {4};   // x = 2
Curve Loop(5) = {3, 12, -7, -11};  Plane Surface(5) = {5};   // side y ~ 1
Curve Loop(6) = {4, 9, -8, -12};   Plane Surface(6) = {6};   // x = 0
Surface Loop(1) = {1, 2, 3, 4, 5, 6};
Volume(1) = {1};

clamped() = Surface In BoundingBox {-eps, -eps, -eps, eps, 1 + eps, 1 + eps};
top() = Surface In BoundingBox {-eps, -eps, 0.4 - eps, 2 + eps, 1 + eps, 1 + eps};
tip() = Surface In BoundingBox {2 - eps, -eps, -eps, 2 + eps, 1 + eps, 1 + eps};
contact() = Surface In BoundingBox {-eps, -eps, -eps, 2 + eps, 1 + eps, eps};
free() = Surface{:};
free() -= {clamped(), top(), tip(), contact()};
Physical Surface("clamped") = {clamped()};
Physical Surface("load_top") = {top()};
Physical Surface("load_end") = {tip()};
Physical Surface("contact") = {contact()};
Physical Surface("free") = {free()};
Physical Volume("body") = {1};
