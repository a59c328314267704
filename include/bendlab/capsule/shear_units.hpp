#pragma once
// Units of the capsule in linear shear flow u_inf = gamma z e_x (paper section 4, docs/conventions.md
// section 2): R = 1 (initial radius), mu = 1 (viscosity), gamma = 1 (shear rate), so time is
// gamma t and
//   G           = mu gamma R / kS         (capillary number)   =>  kS = 1 / G
//   kappa_b_hat = kB / (R^2 kS)           (reduced bending modulus)
//   kappa_b     = kB                      (dimensional)         =>  kB = kappa_b_hat / G
// Either kappa_b_hat or kappa_b is given, never both.
#include <optional>

namespace bendlab {

struct ShearUnits {
  static constexpr double R = 1, mu = 1, gamma = 1;

  double G = 0.1;
  double kappa_b_hat = 0;

  /// Throws bendlab::Error for G <= 0, a negative or non-finite modulus, or both moduli given.
  static ShearUnits from(double G, std::optional<double> kappa_b_hat, std::optional<double> kappa_b);

  double kS() const { return mu * gamma * R / G; }
  double kB() const { return kappa_b_hat * R * R * kS(); }
  double kappa_b() const { return kB(); }
};

}  // namespace bendlab
