#include "bendlab/bending/variational_assembly.hpp"

namespace bendlab {

void assemble_variational_forces(const Points& normal, const Scalars& H, const Scalars& K, const Scalars& lapH,
                                 const Scalars& area, const BendingParameters& p, Points& force_density,
                                 Points& force) {
  const double kappa_b = p.kappa_b;
  const Eigen::Index n = H.size();
  force_density.resize(n, 3);
  force.resize(n, 3);
  if (!p.plain()) {
    // docs/conventions.md §5, with the discrete M = sum_i H_i A_i.
    double M = 0;
    for (Eigen::Index i = 0; i < n; ++i) M += H[i] * area[i];
    const double lambda = p.ade_lambda(M);
    for (Eigen::Index i = 0; i < n; ++i) {
      const double fn = membrane_normal_force(H[i], K[i], lapH[i], p.c0, kappa_b, lambda);
      force_density.row(i) = fn * normal.row(i);
      force.row(i) = area[i] * force_density.row(i);  // eq. (14)
    }
  }
  for (Eigen::Index i = 0; i < n && p.plain(); ++i) {
    // eq. (10) with Lap = div grad (docs/conventions.md §1).
    const double fn = 2.0 * kappa_b * (lapH[i] + 2.0 * H[i] * (H[i] * H[i] - K[i]));
    force_density.row(i) = fn * normal.row(i);
    force.row(i) = area[i] * force_density.row(i);  // eq. (14)
  }
}

BendingResult assemble_variational_result(Points normal, Scalars H, Scalars K, Scalars lapH, Scalars area,
                                          const BendingParameters& p) {
  BendingResult r;
  assemble_variational_forces(normal, H, K, lapH, area, p, r.force_density, r.force);
  r.normal = std::move(normal);
  r.H = std::move(H);
  r.K = std::move(K);
  r.lapH = std::move(lapH);
  r.area = std::move(area);
  return r;
}

void VariationalMethod::evaluate(const Topology& topology, const Points& x, const BendingParameters& params,
                                 BendingResult& out) const {
  fields(topology, x, out);
  assemble_variational_forces(out.normal, out.H, out.K, out.lapH, out.area, params, out.force_density, out.force);
  out.energy.reset();
}

BendingResult VariationalMethod::compute(const Topology& topology, const Points& x, double kappa_b) const {
  BendingResult r;
  evaluate(topology, x, BendingParameters(kappa_b), r);  // plain: eq. (10) unchanged
  return r;
}

void VariationalMethod::compute_into(const Topology& topology, const Points& x, double kappa_b,
                                     BendingResult& out) const {
  evaluate(topology, x, BendingParameters(kappa_b), out);
}

BendingResult VariationalMethod::compute_terms(const Topology& topology, const Points& x,
                                               const BendingParameters& params) const {
  BendingResult r;
  evaluate(topology, x, params, r);
  return r;
}

void VariationalMethod::compute_terms_into(const Topology& topology, const Points& x, const BendingParameters& params,
                                           BendingResult& out) const {
  evaluate(topology, x, params, out);
}

void VariationalMethod::forces(const Topology& topology, const Points& x, double kappa_b, Points& force) const {
  forces_terms(topology, x, BendingParameters(kappa_b), force);
}

void VariationalMethod::forces_terms(const Topology& topology, const Points& x, const BendingParameters& params,
                                     Points& force) const {
  const auto ws = forces_workspace_.acquire();
  fields(topology, x, *ws);
  assemble_variational_forces(ws->normal, ws->H, ws->K, ws->lapH, ws->area, params, ws->force_density, force);
}

}  // namespace bendlab
