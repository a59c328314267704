// bendlab forces: per-vertex bending quantities of one method, optionally with the analytic
// values and the errors of eq. (17).
#include <fmt/format.h>

#include "bendlab/analysis/error_measures.hpp"
#include "bendlab/bending/bending_method.hpp"
#include "bendlab/bending/result_check.hpp"
#include "bendlab/core/csv.hpp"
#include "bendlab/mesh/mesh_io.hpp"
#include "cli_common.hpp"
#include "method_cli.hpp"
#include "command.hpp"

namespace bendlab::cli {
namespace {

struct ForcesArgs {
  std::string mesh, method, shape, out;
  double kappa_b = 1.0, radius = 1.0, surface_tolerance = 1e-6;
  int rings = 0;
  bool small_angle = false;
  std::vector<std::string> options;  // --option key=value
  std::vector<double> axes;
  MembraneTermArgs terms;
};

void run_forces(const ForcesArgs& a) {
  require_positive("--kappa-b", a.kappa_b, true);
  require_extension("--out", a.out, {".csv", ".vtp"});
  require_writable_parent("--out", a.out);
  MethodOptions options;
  if (a.rings != 0) options["rings"] = std::to_string(a.rings);
  if (a.small_angle) options["small_angle"] = "true";
  add_option_assignments(options, a.options);
  const auto method = make_bending_method(a.method, options);
  const BendingParameters params = membrane_parameters(a.kappa_b, a.terms);
  method->check_parameters(params);
  std::unique_ptr<AnalyticSurface> surface;
  if (!a.shape.empty()) surface = surface_from_options(a.shape, a.radius, a.axes);
  const TriMesh mesh = read_mesh(a.mesh);
  if (surface) require_nodes_on_surface(*surface, mesh.positions(), a.surface_tolerance);

  const BendingResult r = method->compute(mesh.topology(), mesh.positions(), params);
  require_finite_result(r, a.method);  // nothing is written from a result with NaN or infinity
  SurfaceFields exact;
  NodeErrors err;
  if (surface) {
    if (!params.plain())
      throw Error("--shape with --c0 or --ade-alpha: the analytic values with c0 and ADE are those of "
                  "bendlab rbc --c0 (forces compares against eq. (10))");
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

const CommandRegistration forces_registration([](CLI::App& app) {
  auto args = std::make_shared<ForcesArgs>();
  auto* cmd = app.add_subcommand("forces", "Compute normals, H, K, Lap H, force density f and node force F "
                                           "of one bending method at every vertex");
  cmd->add_option("--mesh", args->mesh, "input mesh: .off, .obj or .ply")->required()->check(CLI::ExistingFile);
  cmd->add_option("--method", args->method, "bending method: " + method_choices_help() + " (bendlab methods)")
      ->required()->check(CLI::IsMember(bending_method_names()));
  cmd->add_option("--kappa-b", args->kappa_b, "bending modulus kB")->capture_default_str();
  cmd->add_option("--rings", args->rings, "fitting support of E and ED in rings of neighbours (1, 2, 3)")
      ->check(CLI::Range(1, 3));
  add_membrane_term_options(cmd, args->terms, true, "");
  cmd->add_flag("--small-angle", args->small_angle, "method A: small-angle form theta^2/2 of 1 - cos(theta)");
  cmd->add_option("--option", args->options, "method option key=value, repeatable (the options of each method: "
                                             "bendlab methods), e.g. --option rings=2");
  cmd->add_option("--shape", args->shape, "also write the analytic values and errors (eq. 17) of this surface: "
                                          "sphere, rbc, oblate or prolate")
      ->check(CLI::IsMember({"sphere", "rbc", "oblate", "prolate"}));
  cmd->add_option("--radius", args->radius, "radius of the analytic sphere or RBC")->capture_default_str();
  cmd->add_option("--surface-tolerance", args->surface_tolerance,
                  "largest distance of a node from the --shape surface, relative to its size; a mesh with a node "
                  "farther away is refused")
      ->capture_default_str();
  cmd->add_option("--axes", args->axes, "spheroid half-axes a,c")->delimiter(',')->expected(2);
  cmd->add_option("--out", args->out,
                  "output: .csv (x,y,z,nx,ny,nz,H,K,lapH,fx,fy,fz,Fx,Fy,Fz,area[,exact_...,err_...]) or .vtp")
      ->required();
  cmd->callback([args] { run_forces(*args); });
});

}  // namespace
}  // namespace bendlab::cli
