// Where the multipliers of cell i of T_H sit in λ (and in the rows of 𝔹, the radii, h):
// λ = [λ_n (r) | λ_t1 (r) | λ_t2 (r)], the tangential blocks only when the scene has friction.
#pragma once

namespace contact3d {

struct MultiplierLayout {
  int r = 0;  // number of cells
  bool with_friction = true;

  int size() const { return with_friction ? 3 * r : r; }
  int normal(int cell) const { return cell; }
  int t1(int cell) const { return r + cell; }
  int t2(int cell) const { return 2 * r + cell; }
};

}  // namespace contact3d
