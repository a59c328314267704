#include "bendlab/bending/bending_parameters.hpp"

#include <fmt/format.h>

#include <cmath>

#include "bendlab/core/types.hpp"

namespace bendlab {

double BendingParameters::ade_lambda(double M) const {
  if (!has_ade()) return 0.0;
  return ade_alpha * M_PI * kappa_b * (M - ade_m0()) / ade_area;
}

double BendingParameters::ade_energy(double M) const {
  if (!has_ade()) return 0.0;
  const double dm = M - ade_m0();
  return 0.5 * ade_alpha * M_PI * kappa_b * dm * dm / ade_area;
}

void BendingParameters::validate() const {
  if (!std::isfinite(kappa_b)) throw Error(fmt::format("bending modulus must be finite, got {}", kappa_b));
  if (!std::isfinite(c0)) throw Error(fmt::format("spontaneous curvature c0 must be finite, got {}", c0));
  if (!std::isfinite(ade_alpha) || ade_alpha < 0)
    throw Error(fmt::format("ADE alpha must be a finite number >= 0, got {}", ade_alpha));
  if (!has_ade()) return;
  if (!std::isfinite(ade_d) || ade_d <= 0)
    throw Error(fmt::format("ADE leaflet distance d must be positive and finite, got {}", ade_d));
  if (!std::isfinite(ade_area) || ade_area <= 0)
    throw Error(fmt::format("ADE area A must be positive and finite, got {} (give the membrane area)", ade_area));
  if (!std::isfinite(ade_da0)) throw Error(fmt::format("ADE dA0 must be finite, got {}", ade_da0));
  // Each number may be finite while the term is not: its coefficient alpha pi kB / A, or the term
  // at M = 0, where M0 = dA0 / (2 d) dominates it (d = 1e-300 with dA0 = 0.1). Such a term would
  // turn the forces into overflows that surface far from here (as a volume that is no number).
  const double coefficient = ade_alpha * M_PI * kappa_b / ade_area;
  if (!std::isfinite(coefficient) || !std::isfinite(ade_energy(0.0)) || !std::isfinite(ade_lambda(0.0)))
    throw Error(fmt::format("the ADE term alpha pi kB (M - M0)^2 / (2 A) overflows: alpha = {}, kB = {}, A = {}, "
                            "M0 = dA0 / (2 d) = {} (dA0 = {}, d = {})",
                            ade_alpha, kappa_b, ade_area, ade_m0(), ade_da0, ade_d));
}

std::string BendingParameters::describe() const {
  std::string s = fmt::format("kB = {}, c0 = {}", kappa_b, c0);
  if (has_ade()) s += fmt::format(", ADE alpha = {}, d = {}, dA0 = {}, A = {}", ade_alpha, ade_d, ade_da0, ade_area);
  return s;
}

double membrane_normal_force(double H, double K, double lapH, double c0, double kappa_b, double lambda) {
  // docs/conventions.md §5: f_n = 2 kB [Lap H + 2 (H - c0)(H^2 + c0 H - K)] - lambda K.
  return 2.0 * kappa_b * (lapH + 2.0 * (H - c0) * (H * H + c0 * H - K)) - lambda * K;
}

}  // namespace bendlab

// ---- BendingMethod's entry points with c0 and ADE (bending_method.hpp) ----
#include "bendlab/bending/bending_method.hpp"

namespace bendlab {

std::string BendingMethod::membrane_terms_refusal() const {
  return "the method has no spontaneous curvature or area-difference elasticity";
}

void BendingMethod::check_parameters(const BendingParameters& p) const {
  p.validate();
  if (!p.plain() && !supports_membrane_terms())
    throw Error(fmt::format("method {}: c0 != 0 and ADE are refused: {} (docs/conventions.md §5)", name(),
                            membrane_terms_refusal()));
}

BendingResult BendingMethod::compute(const Topology& topology, const Points& x, const BendingParameters& p) const {
  if (p.plain()) return compute(topology, x, p.kappa_b);
  check_parameters(p);
  return compute_terms(topology, x, p);
}

void BendingMethod::compute_into(const Topology& topology, const Points& x, const BendingParameters& p,
                                 BendingResult& out) const {
  if (p.plain()) return compute_into(topology, x, p.kappa_b, out);
  check_parameters(p);
  compute_terms_into(topology, x, p, out);
}

void BendingMethod::forces(const Topology& topology, const Points& x, const BendingParameters& p,
                           Points& force) const {
  if (p.plain()) return forces(topology, x, p.kappa_b, force);
  check_parameters(p);
  forces_terms(topology, x, p, force);
}

std::optional<double> BendingMethod::energy(const Topology& topology, const Points& x,
                                            const BendingParameters& p) const {
  if (p.plain()) return energy(topology, x, p.kappa_b);
  check_parameters(p);
  return energy_terms(topology, x, p);
}

BendingResult BendingMethod::compute_terms(const Topology&, const Points&, const BendingParameters& p) const {
  check_parameters(p);  // throws for a method without the hooks
  throw Error(fmt::format("method {}: compute with c0 / ADE is not implemented", name()));
}

}  // namespace bendlab
