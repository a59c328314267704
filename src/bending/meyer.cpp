#include "bendlab/bending/meyer.hpp"

#include "bendlab/bending/variational_assembly.hpp"
#include "bendlab/geometry/mesh_geometry.hpp"

namespace bendlab {

std::unique_ptr<BendingMethod> MeyerMethod::create(const MethodOptions& options) {
  resolve_method_options(info(), options);  // C takes no options: refuses any
  return std::make_unique<MeyerMethod>();
}

MethodInfo MeyerMethod::info() {
  MethodInfo m{"C", "Meyer: cotangent Laplace-Beltrami operator in eq. (10), eqs. (11)-(12)",
                {}, {}, &MeyerMethod::create};
  return m;
}

BendingResult MeyerMethod::compute(const Topology& topology, const Points& x, double kappa_b) const {
  return compute_terms(topology, x, BendingParameters(kappa_b));  // plain: eq. (10) unchanged
}

// With c0 and ADE the force law of docs/conventions.md §5 from the same H, K, Lap H and n.
BendingResult MeyerMethod::compute_terms(const Topology& topology, const Points& x,
                                         const BendingParameters& params) const {
  const MeshGeometry g = MeshGeometry::compute(topology, x);
  // eqs. (2) and (11) with a_i = A_mixed and the MWA normal.
  Scalars H = mean_curvature_cotan(topology, g, x, g.normal_mwa, g.mixed_area);
  // eq. (11) applied to H.
  Scalars lapH = cotan_laplacian(topology, g, H, g.mixed_area);
  return assemble_variational_result(g.normal_mwa, std::move(H), g.gaussian_curvature, std::move(lapH),
                                     g.mixed_area, params);
}

}  // namespace bendlab
