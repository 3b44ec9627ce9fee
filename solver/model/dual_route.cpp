#include "model/dual_route.hpp"

namespace contact3d {

std::optional<DualMethod> dual_method_for_memory(DualMethod requested, DualMethod resolved, bool dense_Q_fits) {
  if (dense_Q_fits || resolved == DualMethod::MatrixFree) return resolved;
  if (requested == DualMethod::Auto && resolved == DualMethod::Augmented) return DualMethod::MatrixFree;
  return std::nullopt;
}

}  // namespace contact3d
