// The paper's own mesh of the brick (0,3)x(0,1)x(0,1): 3n x n x n cubes, each split into five
// tetrahedra with alternating orientation (Fig. 4), so that every contact node with odd grid
// indices is shared by eight contact triangles (the chessboard of Fig. 5).
// Physical groups: clamped (x=0), load_end (x=3), load_top (z=1), contact (z=0), free, body —
// the same names and tags as geo/brick.geo.
#pragma once

#include "mesh/mesh.hpp"

namespace contact3d {

struct BrickSize {
  int n = 4;  // cubes per unit length (3n x n x n cubes)
  double lx = 3.0, ly = 1.0, lz = 1.0;
};

Mesh make_paper_brick(const BrickSize& size);

}  // namespace contact3d
