#include "model/dual_route.hpp"

#include <algorithm>
#include <limits>

namespace contact3d {

double dense_dual_bytes_per_entry(const QpSettings& qp, int rows) {
  return 2 * 8.0 + (uses_single_products(qp.precision, rows) ? 4.0 : 0.0);
}

std::optional<DualMethod> dual_method_for_memory(DualMethod requested, DualMethod resolved, bool dense_Q_fits) {
  if (dense_Q_fits || resolved == DualMethod::MatrixFree) return resolved;
  if (requested == DualMethod::Auto && resolved == DualMethod::Augmented) return DualMethod::MatrixFree;
  return std::nullopt;
}

bool augmented_crowds_memory(double augmented_lnz, int rows, double dense_bytes, double available) {
  if (!(available > 0)) return false;
  const double q_block = 0.5 * rows * (rows + 1.0);
  const double augmented = kFactorOverhead * 8.0 * augmented_lnz + dense_bytes;
  const double matrix_free = kFactorOverhead * 8.0 * std::max(augmented_lnz - q_block, 0.0);
  return augmented > kTightMemory * available && matrix_free <= kTightMemory * available;
}

double coarse_space_bytes(int multipliers, int groups) { return 4.0 * 8.0 * multipliers * static_cast<double>(groups); }

bool coarse_space_fits(int multipliers, int groups, double available_bytes) {
  return !(available_bytes > 0 && coarse_space_bytes(multipliers, groups) > kCoarseSpaceShare * available_bytes);
}

bool lumped_operators_fit(double bytes, double available_bytes) {
  return !(available_bytes > 0 && bytes > kLumpedShare * available_bytes);
}

double single_factor_budget(double available_bytes) {
  return available_bytes > 0 ? kSingleFactorShare * available_bytes : std::numeric_limits<double>::infinity();
}

bool forward_solves_pay(const AugmentedFactorParts& first_factor, int first_rows, int rows, double available_bytes) {
  if (first_rows <= 0 || first_factor.coupling <= 0) return false;  // no measure of a cell's reach
  const double entries = first_factor.coupling * rows / first_rows;
  return entries < 0.5 * first_factor.leading && (available_bytes <= 0 || 8 * entries < 0.5 * available_bytes);
}

}  // namespace contact3d
