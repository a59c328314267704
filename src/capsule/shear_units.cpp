#include "bendlab/capsule/shear_units.hpp"

#include <fmt/format.h>

#include <cmath>

#include "bendlab/core/types.hpp"

namespace bendlab {

ShearUnits ShearUnits::from(double G, std::optional<double> kappa_b_hat, std::optional<double> kappa_b) {
  if (!(G > 0) || !std::isfinite(G)) throw Error(fmt::format("shear: G must be positive, got {}", G));
  if (kappa_b_hat && kappa_b) throw Error("shear: give kappa_b_hat (dimensionless) or kappa_b (dimensional), not both");
  for (const auto& [name, v] : {std::pair{"kappa_b_hat", kappa_b_hat}, std::pair{"kappa_b", kappa_b}})
    if (v && (!(*v >= 0) || !std::isfinite(*v)))
      throw Error(fmt::format("shear: {} must be non-negative, got {}", name, *v));
  ShearUnits u;
  u.G = G;
  if (kappa_b_hat) u.kappa_b_hat = *kappa_b_hat;
  if (kappa_b) u.kappa_b_hat = *kappa_b / (R * R * u.kS());
  return u;
}

}  // namespace bendlab
