// The coefficient of friction F(t), t = ‖u_t‖ (m): "none" (frictionless), "constant",
// "ramp" (eq. (6.1): `high` for t <= t0, linear down to `low` over a width 2/param, `low`
// beyond) and "table" (piecewise linear through points (t_k, F_k), constant beyond the ends;
// a repeated t makes a jump). Every law is piecewise linear in t; breakpoints() lists where
// its slope may change, which lets the disc radii (5.3) be integrated exactly.
#pragma once

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "base/named_enum.hpp"

namespace contact3d {

// What bounds the tangential multiplier: Tresca (the paper's): ‖λ_t‖ <= F·g with a given slip
// bound g; Coulomb: ‖λ_t‖ <= F·λ_n, the bound is the normal pressure itself (successive
// approximations on (φ, g = λ_n)).
enum class FrictionModel { Tresca, Coulomb };
inline constexpr NameTable<FrictionModel, 2> kFrictionModelNames{
    {{FrictionModel::Tresca, "tresca"}, {FrictionModel::Coulomb, "coulomb"}}};

struct FrictionLaw {
  enum class Kind { None, Constant, Ramp, Table };
  Kind kind = Kind::None;
  double value = 0;                                      // constant
  double high = 0.3, low = 0.2, t0 = 1e-5, param = 6e4;  // ramp (6.1)
  std::vector<std::pair<double, double>> points;         // table

  double operator()(double t) const;
  std::vector<double> breakpoints() const;
  bool depends_on_slip() const { return kind == Kind::Ramp || kind == Kind::Table; }
  // The first slip at which a table law jumps (a repeated t with another F); nullopt otherwise.
  std::optional<double> jump_at() const;
  std::string name() const;
  // Throws InputError with the offending key if the parameters make no sense.
  void validate() const;
};

}  // namespace contact3d
