#include "bendlab/bending/mixed_ed.hpp"

#include "bendlab/bending/belkin.hpp"
#include "bendlab/bending/farutin.hpp"
#include "bendlab/bending/variational_assembly.hpp"
#include "bendlab/geometry/mesh_geometry.hpp"

namespace bendlab {

MixedEDMethod::MixedEDMethod(int rings) : rings_(rings) {
  if (rings < 1) throw Error("method ED: rings must be at least 1, got " + std::to_string(rings));
}

std::unique_ptr<BendingMethod> MixedEDMethod::create(const MethodOptions& options) {
  return std::make_unique<MixedEDMethod>(parse_farutin_rings(options, "ED"));
}

MethodInfo MixedEDMethod::info() {
  MethodInfo m{"ED", "E for n, H and K, D (heat kernel) for Lap H: the paper's conclusion",
                {farutin_rings_option()}, {}, &MixedEDMethod::create};
  m.capabilities.cost = std::string("O(N)");
  return m;
}

BendingResult MixedEDMethod::compute(const Topology& topology, const Points& x, double kappa_b) const {
  return compute_terms(topology, x, BendingParameters(kappa_b));  // plain: eq. (10) unchanged
}

// With c0 and ADE the force law of docs/conventions.md §5 from the same H, K, Lap H and n.
BendingResult MixedEDMethod::compute_terms(const Topology& topology, const Points& x,
                                           const BendingParameters& params) const {
  const MeshGeometry geometry = MeshGeometry::compute(topology, x);
  const std::vector<FarutinFit> fits = farutin_fit(topology, x, geometry.normal_mwa, rings_);
  require_valid_fits(fits, "ED");
  FarutinFields e = farutin_fields(fits);
  Scalars lapH = belkin_laplacian(topology, x, geometry, e.H);
  return assemble_variational_result(std::move(e.normal), std::move(e.H), std::move(e.K), std::move(lapH),
                                     geometry.mixed_area, params);
}

}  // namespace bendlab
