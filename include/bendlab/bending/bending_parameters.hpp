#pragma once
// The membrane parameters a bending method takes (docs/conventions.md §5): the bending modulus kB,
// the spontaneous curvature c0 and area-difference elasticity (ADE; Bian, Litvinov & Koumoutsakos
// 2020), with the energy
//
//   E = 2 kB ∫ (H - c0)^2 dA  +  E_ADE,
//   E_ADE = alpha kB pi / (8 A d^2) (dA - dA0)^2,  dA = 2 d M,  M = ∫ H dA
//         = alpha kB pi / (2 A) (M - M0)^2,        M0 = dA0 / (2 d),
//
// A the membrane area (a fixed parameter, not the area of the current shape), d the leaflet
// distance, dA0 the preferred area difference. Paper eq. (1) is the case c0 = 0, alpha = 0.
//
// The continuum force density (docs/conventions.md §5, from dE = -∫ f . dx dA, H > 0 on a sphere,
// Lap = div grad):
//
//   f = { 2 kB [Lap H + 2 (H - c0)(H^2 + c0 H - K)] - lambda K } n,   lambda = alpha pi kB (M - M0) / A,
//
// which is eq. (10) for c0 = 0, alpha = 0.
#include <string>

namespace bendlab {

struct BendingParameters {
  double kappa_b = 1.0;  ///< bending modulus kB
  double c0 = 0.0;       ///< spontaneous curvature (same sign convention as H: c0 > 0 favours spheres)
  double ade_alpha = 0.0;  ///< ADE ratio alpha = k_ADE / kB (>= 0); 0: no ADE term
  double ade_d = 0.0;      ///< leaflet distance d (> 0 when alpha > 0)
  double ade_da0 = 0.0;    ///< preferred area difference dA0
  double ade_area = 0.0;   ///< membrane area A of the ADE coefficient (> 0 when alpha > 0)

  BendingParameters() = default;
  /// kB alone: the paper's energy (implicit, so a plain modulus converts).
  BendingParameters(double kappa_b) : kappa_b(kappa_b) {}  // NOLINT(google-explicit-constructor)

  bool has_c0() const { return c0 != 0.0; }
  bool has_ade() const { return ade_alpha != 0.0; }
  /// Neither c0 nor ADE: every method takes exactly its paper code path.
  bool plain() const { return !has_c0() && !has_ade(); }
  /// M0 = dA0 / (2 d).
  double ade_m0() const { return ade_da0 / (2.0 * ade_d); }
  /// lambda = alpha pi kB (M - M0) / A: the coefficient of dM in dE_ADE (0 without ADE).
  double ade_lambda(double M) const;
  /// E_ADE = alpha pi kB (M - M0)^2 / (2 A) (0 without ADE).
  double ade_energy(double M) const;
  /// Refuses with a one-line bendlab::Error: non-finite kB or c0, negative alpha, and with
  /// alpha > 0 a leaflet distance or area that is not positive and finite, a non-finite dA0, or
  /// an ADE term that overflows (its coefficient, or the term at M = 0: M0 = dA0 / (2 d) huge).
  void validate() const;
  /// "c0 = 0.5, ADE alpha = 2, d = 0.01, dA0 = 0, A = 12.6" (for logs and run identities).
  std::string describe() const;
};

/// The normal component of the continuum force density above at one point, from H, K, Lap H
/// and the ADE coefficient lambda (ade_lambda(M)). With c0 = 0 and lambda = 0 it is eq. (10).
double membrane_normal_force(double H, double K, double lapH, double c0, double kappa_b, double lambda);

}  // namespace bendlab
