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

// Kept by the method instance and reused from call to call (method_workspace.hpp).
struct MeyerMethod::Workspace {
  MeshGeometry geometry;
  Points lap_x;
};

MeyerMethod::MeyerMethod() = default;
MeyerMethod::~MeyerMethod() = default;

void MeyerMethod::fields(const Topology& topology, const Points& x, BendingResult& out) const {
  const auto ws = workspace_.acquire();
  MeshGeometry& g = ws->geometry;
  MeshGeometry::compute(topology, x, g);
  // eqs. (2) and (11) with a_i = A_mixed and the MWA normal.
  mean_curvature_cotan(topology, g, x, g.normal_mwa, g.mixed_area, ws->lap_x, out.H);
  // eq. (11) applied to H.
  cotan_laplacian(topology, g, out.H, g.mixed_area, out.lapH);
  // The geometry's arrays change places with the result's (no copy; next call they are reused).
  out.normal.swap(g.normal_mwa);
  out.K.swap(g.gaussian_curvature);
  out.area.swap(g.mixed_area);
}

}  // namespace bendlab
