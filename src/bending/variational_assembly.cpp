#include "bendlab/bending/variational_assembly.hpp"

namespace bendlab {

BendingResult assemble_variational_result(Points normal, Scalars H, Scalars K, Scalars lapH, Scalars area,
                                          const BendingParameters& p) {
  const double kappa_b = p.kappa_b;
  const Eigen::Index n = H.size();
  BendingResult r;
  r.force_density.resize(n, 3);
  r.force.resize(n, 3);
  if (!p.plain()) {
    // docs/conventions.md §5, with the discrete M = sum_i H_i A_i.
    double M = 0;
    for (Eigen::Index i = 0; i < n; ++i) M += H[i] * area[i];
    const double lambda = p.ade_lambda(M);
    for (Eigen::Index i = 0; i < n; ++i) {
      const double fn = membrane_normal_force(H[i], K[i], lapH[i], p.c0, kappa_b, lambda);
      r.force_density.row(i) = fn * normal.row(i);
      r.force.row(i) = area[i] * r.force_density.row(i);  // eq. (14)
    }
  }
  for (Eigen::Index i = 0; i < n && p.plain(); ++i) {
    // eq. (10) with Lap = div grad (docs/conventions.md §1).
    const double fn = 2.0 * kappa_b * (lapH[i] + 2.0 * H[i] * (H[i] * H[i] - K[i]));
    r.force_density.row(i) = fn * normal.row(i);
    r.force.row(i) = area[i] * r.force_density.row(i);  // eq. (14)
  }
  r.normal = std::move(normal);
  r.H = std::move(H);
  r.K = std::move(K);
  r.lapH = std::move(lapH);
  r.area = std::move(area);
  return r;
}

}  // namespace bendlab
