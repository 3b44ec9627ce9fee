#include "friction/friction_law.hpp"

#include <algorithm>
#include <cmath>

#include "base/errors.hpp"
#include "base/format.hpp"

namespace contact3d {

double FrictionLaw::operator()(double t) const {
  switch (kind) {
    case Kind::None:
      return 0;
    case Kind::Constant:
      return value;
    case Kind::Ramp: {
      if (t <= t0) return high;
      const double end = t0 + 2.0 / param;
      if (t >= end) return low;
      return high - (high - low) * param / 2.0 * (t - t0);
    }
    case Kind::Table: {
      if (t <= points.front().first) return points.front().second;
      if (t >= points.back().first) return points.back().second;
      // First k with t_k > t; the segment [k-1, k] is linear (a jump has t_{k-1} = t_k).
      auto it = std::upper_bound(points.begin(), points.end(), t, [](double x, const auto& p) { return x < p.first; });
      const auto& [t1, f1] = *std::prev(it);
      const auto& [t2, f2] = *it;
      return f1 + (f2 - f1) * (t - t1) / (t2 - t1);
    }
  }
  return 0;
}

std::optional<double> FrictionLaw::jump_at() const {
  if (kind != Kind::Table) return std::nullopt;
  for (std::size_t k = 1; k < points.size(); ++k)
    if (points[k].first == points[k - 1].first && points[k].second != points[k - 1].second) return points[k].first;
  return std::nullopt;
}

std::vector<double> FrictionLaw::breakpoints() const {
  switch (kind) {
    case Kind::Ramp:
      return {t0, t0 + 2.0 / param};
    case Kind::Table: {
      std::vector<double> out;
      for (const auto& p : points)
        if (out.empty() || p.first > out.back()) out.push_back(p.first);
      return out;
    }
    default:
      return {};
  }
}

std::string FrictionLaw::name() const {
  switch (kind) {
    case Kind::None:
      return "none";
    case Kind::Constant:
      return "constant";
    case Kind::Ramp:
      return "ramp";
    case Kind::Table:
      return "table";
  }
  return "?";
}

void FrictionLaw::validate() const {
  // A coefficient of friction above this is a typo, not a material (and F·g must not overflow).
  constexpr double kMaxCoefficient = 100;
  auto bad = [](const std::string& key, double v) {
    throw InputError("friction." + key + " = " + number(v) + " is not allowed");
  };
  auto coefficient = [&](const std::string& key, double v) {
    if (!std::isfinite(v) || v < 0 || v > kMaxCoefficient)
      bad(key + " (a coefficient: finite, in [0, " + number(kMaxCoefficient) + "])", v);
  };
  switch (kind) {
    case Kind::None:
      return;
    case Kind::Constant:
      coefficient("value", value);
      return;
    case Kind::Ramp:
      coefficient("high", high);
      coefficient("low", low);
      if (!std::isfinite(t0) || t0 < 0) bad("t0 (must be finite and >= 0)", t0);
      if (!std::isfinite(param) || param <= 0) bad("param (must be finite and > 0)", param);
      return;
    case Kind::Table:
      if (points.empty()) throw InputError("friction.points must list at least one [t, F] pair");
      for (std::size_t k = 0; k < points.size(); ++k) {
        const auto& [t, f] = points[k];
        if (!std::isfinite(t) || !std::isfinite(f) || f < 0 || t < 0 || f > kMaxCoefficient)
          throw InputError("friction.points[" + std::to_string(k) + "] must be finite with t >= 0 and F in [0, " +
                           number(kMaxCoefficient) + "]");
        if (k > 0 && t < points[k - 1].first)
          throw InputError("friction.points must be sorted by t (entry " + std::to_string(k) + ")");
        if (k > 1 && t == points[k - 2].first)
          throw InputError("friction.points: at most two entries may share t (a jump), entry " + std::to_string(k));
      }
      return;
  }
}

}  // namespace contact3d
