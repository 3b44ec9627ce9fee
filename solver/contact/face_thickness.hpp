// FaceThickness: how thick the body is above its contact face, against the size of its elements
// there. From the centroid of each contact triangle a ray goes up, along the foundation's normal (+z
// in the solve's frame), to the first boundary face of the body it meets (a face whose outward
// normal points up: the top, or the floor of a cavity); its length is the body's thickness there.
// A body thinner than a cell bends inside it, and the cell averages of (5.4) then let its nodes
// penetrate: contact.cell_size = "auto" starts such a body on smaller cells instead of solving it
// twice (model/contact_solver.cpp, kThinBodyCells).
#pragma once

#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "mesh/mesh.hpp"

namespace contact3d {

struct FaceThickness {
  // Area-weighted median over the contact triangles of the thickness above them (m); infinity when
  // no ray met a face (not expected of a closed body).
  double median = std::numeric_limits<double>::infinity();
  // The contact triangles' typical element size: √(h_x·h_y) of median_extents (contact_face.hpp), the
  // h of "cell_size = 2h" (ContactFace::h_xy, without its lower bound by the shortest edges).
  double element_size = 0;
  // Area-weighted median over the contact triangles of how many elements the mesh has through that
  // thickness: the thickness over the height of the tetrahedron standing on the triangle (its fourth
  // node above the triangle's plane); infinity where no tetrahedron was found. Linear tetrahedra a layer or two through
  // a plate or shell are far too stiff in bending (model/input_warnings.cpp).
  double elements_through = std::numeric_limits<double>::infinity();
  // The body's largest extent in the foundation's plane (the longer side of the mesh's bounding box):
  // the span a plate or shell bends over, also where it touches on a small pad only (a mesh of parts
  // far apart spans their distance).
  double extent = 0;
  int triangles = 0;  // contact triangles (each triangle once)
  int measured = 0;   // of them, those whose ray met a face
};

// The thickness above the triangles of the named contact groups (which must exist: Mesh's
// triangles_of_group throws InputError otherwise). The mesh is in the foundation's frame.
FaceThickness measure_face_thickness(const Mesh& mesh, const std::vector<std::string>& contact_groups);

// One measurement per run, taken where it is first needed: a solve's input warnings, the cells
// contact.cell_size = "auto" starts on, and the second solve "auto" may take all read it (it was taken
// up to three times; `check` of the brick n = 32: 2.60 → 2.56 s of CPU). Holds references: `mesh` and
// `contact_groups` must outlive it.
class FaceThicknessOnce {
 public:
  FaceThicknessOnce(const Mesh& mesh, const std::vector<std::string>& contact_groups)
      : mesh_(mesh), groups_(contact_groups) {}
  const FaceThickness& get() const {
    if (!measured_) measured_ = measure_face_thickness(mesh_, groups_);
    return *measured_;
  }

 private:
  const Mesh& mesh_;
  const std::vector<std::string>& groups_;
  mutable std::optional<FaceThickness> measured_;
};

}  // namespace contact3d
