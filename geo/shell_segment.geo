// A shallow cylindrical shell segment lying convex side down: its axis along y at height R + gap above
// x = 0, inner radius 1 m, thickness 15 mm, half-angle 0.25 rad, 0.4 m long. Its outer face's lowest line
// lies at z = gap (0 by default: touching the plane along y). Groups: "contact" the outer face, "inner" the
// concave face, "ends" the faces y = 0 and y = 0.4, "edges" the two straight side faces. Element size h.
SetFactory("OpenCASCADE");
If (!Exists(h))
  h = 0.0075;
EndIf
If (!Exists(gap))
  gap = 0.0;
EndIf
inner_radius = 1.0;
thickness = 0.015;
half_angle = 0.25;
length = 0.4;
tol = 1e-6;
outer_radius = inner_radius + thickness;
axis_z = outer_radius + gap;
centre = newp; Point(centre) = {0, 0, axis_z};
outer_left = newp; Point(outer_left) = {-outer_radius * Sin(half_angle), 0, axis_z - outer_radius * Cos(half_angle)};
outer_right = newp; Point(outer_right) = {outer_radius * Sin(half_angle), 0, axis_z - outer_radius * Cos(half_angle)};
inner_right = newp; Point(inner_right) = {inner_radius * Sin(half_angle), 0, axis_z - inner_radius * Cos(half_angle)};
inner_left = newp; Point(inner_left) = {-inner_radius * Sin(half_angle), 0, axis_z - inner_radius * Cos(half_angle)};
outer_arc = newl; Circle(outer_arc) = {outer_left, centre, outer_right};
right_side = newl; Line(right_side) = {outer_right, inner_right};
inner_arc = newl; Circle(inner_arc) = {inner_right, centre, inner_left};
left_side = newl; Line(left_side) = {inner_left, outer_left};
Curve Loop(1) = {outer_arc, right_side, inner_arc, left_side};
Plane Surface(1) = {1};
Extrude {0, length, 0} { Surface{1}; }
Mesh.MeshSizeMax = h;
x_out = outer_radius * Sin(half_angle);
x_in = inner_radius * Sin(half_angle);
z_rim_out = axis_z - outer_radius * Cos(half_angle);
z_rim_in = axis_z - inner_radius * Cos(half_angle);
contact() = Surface In BoundingBox {-x_out - tol, -tol, gap - tol, x_out + tol, length + tol, z_rim_out + tol};
ends() = Surface In BoundingBox {-2, -tol, -1, 2, tol, 3};
ends() += Surface In BoundingBox {-2, length - tol, -1, 2, length + tol, 3};
edges() = Surface In BoundingBox {-x_out - tol, -tol, z_rim_out - tol, -x_in + tol, length + tol, z_rim_in + tol};
edges() += Surface In BoundingBox {x_in - tol, -tol, z_rim_out - tol, x_out + tol, length + tol, z_rim_in + tol};
inner() = Surface{:};
inner() -= {contact(), ends(), edges()};
Physical Surface("contact") = {contact()};
Physical Surface("inner") = {inner()};
Physical Surface("ends") = {ends()};
Physical Surface("edges") = {edges()};
Physical Volume("body") = {Volume{:}};
