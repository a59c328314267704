// bendlab shear: an initially spherical capsule (neo-Hookean membrane + bending) in linear shear
// flow, by the boundary integral method (paper section 4, --solver bim) or by the immersed-boundary
// lattice Boltzmann method (section 4.3.2, --solver lbm). Argument parsing only: the membrane is a
// MembraneModel, the flow a BimCapsuleSolver or an LbmCapsuleSolver, and the run folder (timeseries.csv, snapshots,
// checkpoint.json, summary.json) belongs to run_capsule (bendlab/capsule/capsule_run.hpp).
// D_theta.png is drawn by scripts/plot_shear.py, found at run time.
#include <fmt/format.h>

#include <filesystem>
#include <iostream>
#include <optional>
#include <regex>

#include "bendlab/bending/bending_method.hpp"
#include "bendlab/capsule/capsule_run.hpp"
#include "bendlab/core/helper_program.hpp"
#include "bendlab/capsule/shear_units.hpp"
#include "bendlab/flow/bim/bim_capsule_solver.hpp"
#include "bendlab/flow/lbm/lbm_capsule_solver.hpp"
#include "bendlab/membrane/espresso_volume_force.hpp"
#include "bendlab/integrate/cash_karp.hpp"
#include "bendlab/mesh/generators.hpp"
#include "bendlab/mesh/mesh_io.hpp"
#include "cli_common.hpp"
#include "method_cli.hpp"
#include "command.hpp"

namespace fs = std::filesystem;

namespace bendlab::cli {
namespace {

struct ShearArgs {
  std::string solver = "bim", method = "none", mesh = "mt1:1280", out, plot_script;
  double G = 0.1, t_end = 10, snapshot_every = 0.5, rtol = 1e-7, atol = 1e-6;
  std::optional<double> kappa_b_hat, kappa_b;
  int rings = 0;
  std::int64_t stop_after_steps = 0;
  bool resume = false, plot = true;
  // --solver lbm (lattice units; box in multiples of R)
  double radius_lu = 6, tau = 1, reynolds = 0.2, sample_every = 1e-3;
  std::vector<double> box = {8, 8, 10};
  std::string kernel = "phi2";
  // Which options the user gave (the other solver's options are refused).
  bool given_tolerance = false, given_lattice = false;
};

lbm::IbKernel parse_kernel(const std::string& k) {
  if (k == "phi2") return lbm::IbKernel::Phi2;
  if (k == "phi3") return lbm::IbKernel::Phi3;
  return lbm::IbKernel::Phi4;
}

/// "mt1:N", "mt2:N" (N triangles of the homogeneous family), "inh:mt1", "inh:mt2" (320 triangles
/// and three Rivara passes, as in the paper), or a mesh file.
TriMesh capsule_mesh(const std::string& spec) {
  std::smatch m;
  if (std::regex_match(spec, m, std::regex(R"((mt1|mt2|octa):(\d+))"))) {
    const MeshFamily family = parse_mesh_family(m[1]);
    const long triangles = std::stol(m[2]);
    const int level = level_with_triangles(family, triangles);
    if (level < 0 || level > 7)
      throw Error(fmt::format("--mesh {}: {} has no level with {} triangles (up to 7 steps of 4x refinement)", spec,
                              m[1].str(), triangles));
    return sphere_mesh(family, level);
  }
  if (std::regex_match(spec, m, std::regex(R"(inh:(mt1|mt2))"))) return sphere_mesh(parse_mesh_family(m[1]), 2, 3);
  if (!fs::exists(spec))
    throw Error(fmt::format("--mesh '{}' is neither mt1:N, mt2:N, inh:mt1, inh:mt2 nor an existing file", spec));
  return read_mesh(spec);
}

/// D_theta.png from scripts/plot_shear.py (--plot-script, else found at run time: an install's
/// share/bendlab/scripts, or scripts/ above the executable), started with an argument vector.
void plot(const ShearArgs& a) {
  const fs::path script = find_helper_script("plot_shear.py", a.plot_script);
  if (script.empty() || !fs::is_regular_file(script)) {
    note(a.plot_script.empty() ? "warning: the plot was not made (scripts/plot_shear.py not found; see --plot-script)"
                               : fmt::format("warning: the plot was not made (--plot-script '{}' not found)",
                                             a.plot_script));
    return;
  }
  if (run_helper_program({"/usr/bin/python3", script.string(), a.out}) != 0)
    note("warning: the plot was not made (needs /usr/bin/python3 with matplotlib)");
}

void run_shear(const ShearArgs& a) {
  // Everything is checked before any work starts.
  require_positive("--G", a.G);
  if (a.kappa_b_hat) require_positive("--kappa-b-hat", *a.kappa_b_hat, true);
  if (a.kappa_b) require_positive("--kappa-b", *a.kappa_b, true);
  require_positive("--t-end", a.t_end);
  require_positive("--snapshot-every", a.snapshot_every);
  require_positive("--rtol", a.rtol);
  require_positive("--atol", a.atol);
  if (a.solver == "lbm" && a.given_tolerance)
    throw Error("--rtol and --atol are for --solver bim: the lattice Boltzmann solver takes fixed steps");
  if (a.solver == "bim" && a.given_lattice)
    throw Error("--radius-lu, --box, --tau, --reynolds, --kernel and --sample-every are for --solver lbm");
  if (a.solver == "lbm") {
    require_positive("--radius-lu", a.radius_lu);
    require_positive("--sample-every", a.sample_every);
    if (a.box.size() != 3) throw Error("--box needs three multiples of R: x,y,z");
    // tau, Re, the box and the walls are checked by lbm::capsule_run_parameters below, before any work.
  }
  const ShearUnits units = ShearUnits::from(a.G, a.kappa_b_hat, a.kappa_b);
  if (a.method == "none" && units.kappa_b_hat > 0)
    throw Error("--kappa-b-hat or --kappa-b > 0 needs a bending --method (" + method_names_joined() + ")");
  std::shared_ptr<const BendingMethod> bending;
  if (a.method != "none") {
    MethodOptions options;
    if (a.rings != 0) options["rings"] = std::to_string(a.rings);
    bending = make_bending_method(a.method, options);
  }
  if (fs::exists(a.out) && !fs::is_directory(a.out)) throw Error(fmt::format("--out '{}' is a file, not a folder", a.out));
  if (a.resume && !fs::exists(fs::path(a.out) / "checkpoint.json"))
    throw Error(fmt::format("--resume: no checkpoint in '{}' to resume from", a.out));
  const TriMesh mesh = capsule_mesh(a.mesh);

  MembraneParameters mp;
  mp.kS = units.kS();
  mp.kB = units.kB();
  mp.bending = bending;
  auto membrane = std::make_shared<const MembraneModel>(mesh, mp);
  std::unique_ptr<CapsuleSolver> solver;
  nlohmann::json lattice_arguments = nlohmann::json::object(), summary_fields = {{"rtol", a.rtol}, {"atol", a.atol}};
  double lattice_nodes = 0, lattice_gamma = 0;
  if (a.solver == "bim") {
    auto membrane = std::make_shared<const MembraneModel>(mesh, mp);
    CashKarpOptions ck;
    ck.rtol = a.rtol;
    ck.atol = a.atol;
    BimOptions bim;
    bim.mu = ShearUnits::mu;
    bim.gamma = ShearUnits::gamma;
    solver = std::make_unique<BimCapsuleSolver>(membrane, std::make_unique<CashKarp>(ck), bim);
  } else {
    lbm::CapsuleRunInput in;
    in.radius = a.radius_lu;
    in.tau = a.tau;
    in.box_x = a.box[0];
    in.box_y = a.box[1];
    in.box_z = a.box[2];
    in.reynolds = a.reynolds;
    in.G = units.G;
    in.kB_hat = units.kappa_b_hat;
    in.kV_over_kS = kEspressoVolumeRatio;
    in.gamma_t_end = a.t_end;
    in.kernel = parse_kernel(a.kernel);
    const lbm::CapsuleRunParameters p = lbm::capsule_run_parameters(in);
    for (const std::string& w : p.warnings) note("warning: " + w);
    mp.volume_force = std::make_shared<const EspressoVolumeForce>(EspressoVolumeForce::for_membrane(mp.kS));
    auto membrane = std::make_shared<const MembraneModel>(mesh, mp);
    LbmSolverOptions lo;
    lo.radius = a.radius_lu;
    lo.lattice = p;
    lo.kernel = in.kernel;
    lo.sample_every = a.sample_every;
    solver = std::make_unique<LbmCapsuleSolver>(membrane, lo);
    lattice_nodes = static_cast<double>(p.nx) * p.ny * p.nz;
    lattice_gamma = p.shear_rate;
    lattice_arguments = {{"radius_lu", a.radius_lu}, {"box", a.box},      {"tau", a.tau},
                         {"reynolds", a.reynolds},   {"kernel", a.kernel}, {"sample_every", a.sample_every},
                         {"kappa_v_over_kappa_s", kEspressoVolumeRatio}};
    summary_fields = {{"lattice",
                       {{"nodes", {p.nx, p.ny, p.nz}},
                        {"nu", p.nu},
                        {"wall_velocity", p.wall_velocity},
                        {"shear_rate", p.shear_rate},
                        {"mach", p.mach},
                        {"reynolds", p.reynolds},
                        {"particle_reynolds", p.particle_reynolds},
                        {"kS", p.kS},
                        {"kB", p.kB},
                        {"kV", p.kV},
                        {"steps", p.steps},
                        {"sample_steps", static_cast<LbmCapsuleSolver&>(*solver).sample_steps()}}}};
  }

  CapsuleRunOptions o;
  o.folder = a.out;
  o.t_end = a.t_end;
  o.snapshot_every = a.snapshot_every;
  o.resume = a.resume;
  o.stop_after_steps = a.stop_after_steps;
  o.arguments = {{"solver", a.solver}, {"method", a.method},  {"rings", a.rings},
                 {"mesh", a.mesh},     {"G", units.G},        {"kappa_b_hat", units.kappa_b_hat},
                 {"kappa_b", units.kappa_b()}};
  for (const auto& [key, value] : lattice_arguments.items()) o.arguments[key] = value;
  o.summary_fields = summary_fields;
  o.on_note = note;
  o.on_progress = [&](const CapsuleProgress& p) {
    std::string line = fmt::format(
        "gamma t = {:7.4f} / {:g} ({:3.0f}%)  steps {:6d}  gamma dt {:.2e}  D {:.5f}  theta {:.4f}  elapsed {:.0f} s  "
        "ETA {:.0f} s",
        p.time, p.t_end, 100 * (p.time - p.t_start) / (p.t_end - p.t_start), p.steps, p.dt, p.D, p.theta,
        p.elapsed_seconds, p.eta_seconds);
    // Lattice node updates per second of this part (fluid + membrane + IBM).
    if (lattice_gamma > 0 && p.elapsed_seconds > 0)
      line += fmt::format("  {:.1f} MLUPS", (p.time - p.t_start) / lattice_gamma * lattice_nodes / p.elapsed_seconds / 1e6);
    note(line);
  };
  const CapsuleRunResult result = run_capsule(*solver, o);
  if (!result.finished) {
    note(fmt::format("stopped after {} steps at gamma t = {:.6g}; continue with --resume", a.stop_after_steps,
                     solver->time()));
    return;
  }
  std::cout << result.summary.dump() << std::endl;
  if (a.plot) plot(a);
}

const CommandRegistration registration([](CLI::App& app) {
  auto args = std::make_shared<ShearArgs>();
  auto* cmd = app.add_subcommand("shear", "Simulate an initially spherical capsule (neo-Hookean membrane plus "
                                          "bending) in linear shear flow u = gamma z e_x at zero Reynolds number");
  cmd->add_option("--solver", args->solver,
                  "flow solver: bim (boundary integral method) or lbm (immersed-boundary lattice Boltzmann)")
      ->check(CLI::IsMember({"bim", "lbm"}))->capture_default_str();
  cmd->add_option("--method", args->method, "bending method: none, " + method_names_joined())
      ->check(CLI::IsMember(method_choices_with_none()))->capture_default_str();
  cmd->add_option("--rings", args->rings, "fitting support of E and ED (1, 2, 3)")->check(CLI::Range(1, 3));
  cmd->add_option("--mesh", args->mesh, "mt1:N or mt2:N (N triangles: 320, 1280, 5120, ...), inh:mt1 or inh:mt2 "
                                        "(320 triangles + 3 Rivara passes), or a mesh file (.off, .obj, .ply)")
      ->capture_default_str();
  cmd->add_option("--G", args->G, "dimensionless shear rate mu gamma R / kS (units R = mu = gamma = 1, kS = 1/G)")
      ->capture_default_str();
  auto* hat = cmd->add_option("--kappa-b-hat", args->kappa_b_hat,
                              "dimensionless bending modulus kappa_b_hat = kB / (R^2 kS) (default 0)");
  auto* dim = cmd->add_option("--kappa-b", args->kappa_b,
                              "dimensional bending modulus kB = kappa_b_hat / G (R = mu = gamma = 1)");
  hat->excludes(dim);
  cmd->add_option("--t-end", args->t_end, "end of the run in gamma t")->capture_default_str();
  auto tolerance = [args](const std::string&) { args->given_tolerance = true; };
  auto lattice = [args](const std::string&) { args->given_lattice = true; };
  cmd->add_option("--rtol", args->rtol, "relative tolerance of the Cash-Karp stepper (bim)")
      ->capture_default_str()->each(tolerance);
  cmd->add_option("--atol", args->atol, "absolute tolerance of the Cash-Karp stepper, in units of R (bim)")
      ->capture_default_str()->each(tolerance);
  cmd->add_option("--radius-lu", args->radius_lu, "capsule radius R in lattice units (lbm)")
      ->capture_default_str()->each(lattice);
  cmd->add_option("--box", args->box, "box edges in multiples of R: x,y,z (z: wall distance; lbm)")
      ->delimiter(',')->expected(3)->capture_default_str()->each(lattice);
  cmd->add_option("--tau", args->tau, "LBM relaxation time, > 1/2 (viscosity (tau - 1/2)/3; lbm)")
      ->capture_default_str()->each(lattice);
  cmd->add_option("--reynolds", args->reynolds,
                  "Reynolds number Re = R v / nu of the wall speed v, as in the paper (warns above its 0.3; "
                  "particle Re = gamma R^2 / nu is in summary.json; lbm)")
      ->capture_default_str()->each(lattice);
  cmd->add_option("--kernel", args->kernel, "immersed-boundary kernel: phi2 (ESPResSo's), phi3, phi4 (lbm)")
      ->check(CLI::IsMember({"phi2", "phi3", "phi4"}))->capture_default_str()->each(lattice);
  cmd->add_option("--sample-every", args->sample_every,
                  "gamma t between time-series rows, rounded to whole lattice steps (lbm)")
      ->capture_default_str()->each(lattice);
  cmd->add_option("--snapshot-every", args->snapshot_every, "gamma t between .vtp snapshots and checkpoints")
      ->capture_default_str();
  cmd->add_flag("--resume", args->resume, "continue the run in --out from its last checkpoint");
  cmd->add_option("--stop-after-steps", args->stop_after_steps,
                  "stop after this many accepted steps (no summary; continue with --resume)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_flag("!--no-plot", args->plot, "do not draw D_theta.png");
  cmd->add_option("--plot-script", args->plot_script,
                  "plot_shear.py to draw D_theta.png with (default: found beside the executable)");
  cmd->add_option("--out", args->out, "output folder (created if missing)")->required();
  cmd->callback([args] { run_shear(*args); });
});

}  // namespace
}  // namespace bendlab::cli
