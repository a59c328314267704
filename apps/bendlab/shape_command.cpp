// bendlab shape: exact differential geometry of an analytic surface at the nodes of a mesh.
#include <fmt/format.h>

#include "bendlab/core/csv.hpp"
#include "bendlab/mesh/mesh_io.hpp"
#include "cli_common.hpp"
#include "command.hpp"

namespace bendlab::cli {
namespace {

struct ShapeArgs {
  std::string mesh, shape = "rbc", out;
  double kappa_b = 1.0, radius = 1.0, surface_tolerance = 1e-6;
  std::vector<double> axes;
};

void run_shape(const ShapeArgs& a) {
  require_positive("--kappa-b", a.kappa_b, true);
  require_extension("--out", a.out, {".csv", ".vtp"});
  require_writable_parent("--out", a.out);
  const auto surface = surface_from_options(a.shape, a.radius, a.axes);
  const TriMesh mesh = read_mesh(a.mesh);
  require_nodes_on_surface(*surface, mesh.positions(), a.surface_tolerance);
  const SurfaceFields s = surface->evaluate(mesh.positions(), a.kappa_b);
  if (extension_of(a.out) == ".csv") {
    CsvTable t;
    t.add({"x", "y", "z"}, mesh.positions());
    t.add({"nx", "ny", "nz"}, s.normal);
    t.add("H", s.H);
    t.add("K", s.K);
    t.add("lapH", s.lapH);
    t.add({"fx", "fy", "fz"}, s.f);
    t.add("f_normal", s.f_normal);
    t.write(a.out);
  } else {
    VertexFields fields;
    fields.scalars = {{"H", s.H}, {"K", s.K}, {"lapH", s.lapH}, {"f_normal", s.f_normal}};
    fields.vectors = {{"normal", s.normal}, {"f", s.f}};
    write_mesh(a.out, mesh.topology(), mesh.positions(), fields);
  }
}

const CommandRegistration shape_registration([](CLI::App& app) {
  auto args = std::make_shared<ShapeArgs>();
  auto* cmd = app.add_subcommand("shape", "Write the exact normal, H, K, Lap H and force density of an analytic "
                                          "surface at the nodes of a mesh (nodes must lie on the surface)");
  cmd->add_option("--mesh", args->mesh, "input mesh: .off, .obj or .ply")->required()->check(CLI::ExistingFile);
  cmd->add_option("--shape", args->shape, "sphere, rbc, oblate or prolate")
      ->check(CLI::IsMember({"sphere", "rbc", "oblate", "prolate"}))->capture_default_str();
  cmd->add_option("--kappa-b", args->kappa_b, "bending modulus kB")->capture_default_str();
  cmd->add_option("--radius", args->radius, "sphere radius, or the RBC's large half-axis R")->capture_default_str();
  cmd->add_option("--surface-tolerance", args->surface_tolerance,
                  "largest distance of a node from the --shape surface, relative to its size; a mesh with a node "
                  "farther away is refused")
      ->capture_default_str();
  cmd->add_option("--axes", args->axes, "spheroid half-axes a,c (equatorial, polar)")->delimiter(',')->expected(2);
  cmd->add_option("--out", args->out, "output: .csv (x,y,z,nx,ny,nz,H,K,lapH,fx,fy,fz,f_normal) or .vtp")->required();
  cmd->callback([args] { run_shape(*args); });
});

}  // namespace
}  // namespace bendlab::cli
