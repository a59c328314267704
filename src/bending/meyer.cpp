#include "bendlab/bending/meyer.hpp"

#include "bendlab/geometry/mesh_geometry.hpp"

namespace bendlab {

BendingResult assemble_variational_result(Points normal, Scalars H, Scalars K, Scalars lapH, Scalars area,
                                          double kappa_b) {
  const Eigen::Index n = H.size();
  BendingResult r;
  r.force_density.resize(n, 3);
  r.force.resize(n, 3);
  for (Eigen::Index i = 0; i < n; ++i) {
    // eq. (10) with Lap = div grad (CONVENTIONS.md section 1).
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

std::unique_ptr<BendingMethod> MeyerMethod::create(const MethodOptions& options) {
  if (!options.empty()) throw Error("method C: unknown option '" + options.begin()->first + "'");
  return std::make_unique<MeyerMethod>();
}

BendingResult MeyerMethod::compute(const Topology& topology, const Points& x, double kappa_b) const {
  const MeshGeometry g = MeshGeometry::compute(topology, x);
  // eqs. (2) and (11) with a_i = A_mixed and the MWA normal.
  Scalars H = mean_curvature_cotan(topology, g, x, g.normal_mwa, g.mixed_area);
  // eq. (11) applied to H.
  Scalars lapH = cotan_laplacian(topology, g, H, g.mixed_area);
  return assemble_variational_result(g.normal_mwa, std::move(H), g.gaussian_curvature, std::move(lapH),
                                     g.mixed_area, kappa_b);
}

}  // namespace bendlab
