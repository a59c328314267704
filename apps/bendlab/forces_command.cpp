// bendlab forces: per-vertex bending quantities of one method, optionally with the analytic
// values and the errors of eq. (17).
#include <fmt/format.h>

#include "bendlab/analysis/error_measures.hpp"
#include "bendlab/bending/bending_method.hpp"
#include "bendlab/core/csv.hpp"
#include "bendlab/mesh/mesh_io.hpp"
#include "cli_common.hpp"
#include "command.hpp"

namespace bendlab::cli {
namespace {

struct ForcesArgs {
  std::string mesh, method, shape, out;
  double kappa_b = 1.0, radius = 1.0;
  int rings = 0;
  bool small_angle = false;
  std::vector<double> axes;
};

void run_forces(const ForcesArgs& a) {
  require_positive("--kappa-b", a.kappa_b, true);
  require_extension("--out", a.out, {".csv", ".vtp"});
  require_writable_parent("--out", a.out);
  MethodOptions options;
  if (a.rings != 0) options["rings"] = std::to_string(a.rings);
  if (a.small_angle) options["small_angle"] = "true";
  const auto method = make_bending_method(a.method, options);
  std::unique_ptr<AnalyticSurface> surface;
  if (!a.shape.empty()) surface = surface_from_options(a.shape, a.radius, a.axes);
  const TriMesh mesh = read_mesh(a.mesh);

  const BendingResult r = method->compute(mesh.topology(), mesh.positions(), a.kappa_b);
  SurfaceFields exact;
  NodeErrors err;
  if (surface) {
    exact = surface->evaluate(mesh.positions(), a.kappa_b);
    err = node_errors(exact, surface->maxima(a.kappa_b), r, a.kappa_b);
  }
  if (extension_of(a.out) == ".csv") {
    CsvTable t;
    t.add({"x", "y", "z"}, mesh.positions());
    t.add({"nx", "ny", "nz"}, r.normal);
    t.add("H", r.H);
    t.add("K", r.K);
    t.add("lapH", r.lapH);
    t.add({"fx", "fy", "fz"}, r.force_density);
    t.add({"Fx", "Fy", "Fz"}, r.force);
    t.add("area", r.area);
    if (surface) {
      t.add({"exact_nx", "exact_ny", "exact_nz"}, exact.normal);
      t.add("exact_H", exact.H);
      t.add("exact_K", exact.K);
      t.add("exact_lapH", exact.lapH);
      t.add({"exact_fx", "exact_fy", "exact_fz"}, exact.f);
      for (Quantity q : kAllQuantities) t.add("err_" + to_string(q), err[q]);
    }
    t.write(a.out);
  } else {
    VertexFields fields;
    fields.scalars = {{"H", r.H}, {"K", r.K}, {"lapH", r.lapH}, {"area", r.area}};
    fields.vectors = {{"normal", r.normal}, {"f", r.force_density}, {"F", r.force}};
    if (surface) {
      fields.scalars.push_back({"exact_H", exact.H});
      fields.scalars.push_back({"exact_lapH", exact.lapH});
      fields.vectors.push_back({"exact_f", exact.f});
      for (Quantity q : kAllQuantities) fields.scalars.push_back({"err_" + to_string(q), err[q]});
    }
    write_mesh(a.out, mesh.topology(), mesh.positions(), fields);
  }
  if (r.energy) note(fmt::format("bending energy E_B = {:.12g}", *r.energy));
}

const CommandRegistration registration([](CLI::App& app) {
  auto args = std::make_shared<ForcesArgs>();
  auto* cmd = app.add_subcommand("forces", "Compute normals, H, K, Lap H, force density f and node force F "
                                           "of one bending method at every vertex");
  cmd->add_option("--mesh", args->mesh, "input mesh: .off, .obj or .ply")->required()->check(CLI::ExistingFile);
  cmd->add_option("--method", args->method, "A (Kantor-Nelson), B (Gompper-Kroll), C (Meyer), D (Belkin), "
                                            "E (Farutin), ED (E for H, K, n; D for Lap H), S (Loop subdivision)")
      ->required()->check(CLI::IsMember({"A", "B", "C", "D", "E", "ED", "S"}));
  cmd->add_option("--kappa-b", args->kappa_b, "bending modulus kB")->capture_default_str();
  cmd->add_option("--rings", args->rings, "fitting support of E and ED in rings of neighbours (1, 2, 3)")
      ->check(CLI::Range(1, 3));
  cmd->add_flag("--small-angle", args->small_angle, "method A: small-angle form theta^2/2 of 1 - cos(theta)");
  cmd->add_option("--shape", args->shape, "also write the analytic values and errors (eq. 17) of this surface: "
                                          "sphere, rbc, oblate or prolate")
      ->check(CLI::IsMember({"sphere", "rbc", "oblate", "prolate"}));
  cmd->add_option("--radius", args->radius, "radius of the analytic sphere or RBC")->capture_default_str();
  cmd->add_option("--axes", args->axes, "spheroid half-axes a,c")->delimiter(',')->expected(2);
  cmd->add_option("--out", args->out,
                  "output: .csv (x,y,z,nx,ny,nz,H,K,lapH,fx,fy,fz,Fx,Fy,Fz,area[,exact_...,err_...]) or .vtp")
      ->required();
  cmd->callback([args] { run_forces(*args); });
});

}  // namespace
}  // namespace bendlab::cli
