#include "bendlab/bending/mixed_ed.hpp"

#include "bendlab/bending/belkin.hpp"
#include "bendlab/bending/farutin.hpp"
#include "bendlab/bending/variational_assembly.hpp"
#include "bendlab/geometry/mesh_geometry.hpp"

namespace bendlab {

// Kept by the method instance and reused from call to call (method_workspace.hpp).
struct MixedEDMethod::Workspace {
  MeshGeometry geometry;
  std::vector<FarutinFit> fits;
  FarutinWorkspace buffers;
  BelkinLaplacian laplacian;
};

MixedEDMethod::MixedEDMethod(int rings) : rings_(rings) {
  if (rings < 1) throw Error("method ED: rings must be at least 1, got " + std::to_string(rings));
}

MixedEDMethod::~MixedEDMethod() = default;

std::unique_ptr<BendingMethod> MixedEDMethod::create(const MethodOptions& options) {
  return std::make_unique<MixedEDMethod>(parse_farutin_rings(options, "ED"));
}

MethodInfo MixedEDMethod::info() {
  MethodInfo m{"ED", "E for n, H and K, D (heat kernel) for Lap H: the paper's conclusion",
                {farutin_rings_option()}, {}, &MixedEDMethod::create};
  m.capabilities.cost = std::string("O(N)");
  return m;
}

void MixedEDMethod::fields(const Topology& topology, const Points& x, BendingResult& out) const {
  const auto ws = workspace_.acquire();
  MeshGeometry& geometry = ws->geometry;
  MeshGeometry::compute(topology, x, geometry);
  farutin_fit(topology, x, geometry.normal_mwa, rings_, ws->buffers, ws->fits);
  require_valid_fits(ws->fits, "ED");
  farutin_fields(ws->fits, out.normal, out.H, out.K);
  // belkin_laplacian(topology, x, geometry, H) with the operator's buffers kept.
  ws->laplacian.prepare(topology, x, geometry, BelkinOptions{});
  ws->laplacian.apply_into(out.H, out.lapH);
  out.area.swap(geometry.mixed_area);  // no copy; next call the arrays are reused
}

}  // namespace bendlab
