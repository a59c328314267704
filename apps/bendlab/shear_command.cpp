// bendlab shear: a capsule (neo-Hookean or Skalak membrane + bending; a sphere, or with --shape a red
// blood cell or a spheroid, stress-free as it starts or in a --reference-shape) in linear shear
// flow, by the boundary integral method (paper section 4, --solver bim) or the immersed-boundary
// lattice Boltzmann method (section 4.3.2, --solver lbm). Argument parsing only: the run is
// run_shear (bendlab/flow/shear_run.hpp), whose folder (timeseries.csv, snapshots,
// checkpoint.json, summary.json) belongs to run_capsule (bendlab/capsule/capsule_run.hpp).
// D_theta.png is drawn by scripts/plot_shear.py, found at run time.
#include <fmt/format.h>

#include <filesystem>
#include <iostream>
#include <optional>

#include "bendlab/core/helper_program.hpp"
#include "bendlab/flow/shear_run.hpp"
#include "cli_common.hpp"
#include "method_cli.hpp"
#include "command.hpp"
#ifdef BENDLAB_HAVE_MPI
#include "bendlab/parallel/mpi_lbm_capsule_solver.hpp"
#endif

namespace fs = std::filesystem;

namespace bendlab::cli {
namespace {

struct ShearArgs {
  std::string solver = "bim", method = "none", mesh = "mt1:1280", out, plot_script, integrator = "cash-karp",
              membrane = "neo-hookean", bim_quadrature = "all7";
  double skalak_c = 1;
  double G = 0.1, t_end = 10, snapshot_every = 0.5, rtol = 1e-7, atol = 1e-6;
  std::optional<double> kappa_b_hat, kappa_b;
  int rings = 0;
  std::vector<std::string> options;  // --option key=value
  std::int64_t stop_after_steps = 0, max_steps = 0;
  bool resume = false, overwrite = false, plot = true;
  LatticeRunSpec lattice;  // --solver lbm
  MembraneTermArgs terms;  // --c0, --ade-*
  CapsuleShapeSpec shape;  // --shape, --aspect, --tilt, --reference-shape, --reference-aspect
  // Which options the user gave (the other solver's options are refused).
  bool given_tolerance = false, given_lattice = false;
};

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
  try {
    if (run_helper_program({"/usr/bin/python3", script.string(), a.out}) != 0)
      note("warning: the plot was not made (needs /usr/bin/python3 with matplotlib)");
  } catch (const Error& e) {  // the interpreter cannot start: still only a plot not made
    note(fmt::format("warning: the plot was not made ({})", e.what()));
  }
}

void shear(const ShearArgs& a) {
  if (a.solver == "lbm" && a.given_tolerance)
    throw Error("--integrator, --rtol, --atol and --bim-quadrature are for --solver bim: the lattice Boltzmann "
                "solver takes fixed steps");
  if (a.solver == "lbm" && a.max_steps > 0)
    throw Error("--max-steps is for --solver bim: the lattice Boltzmann solver's step count is fixed by --t-end");
  if (a.solver == "bim" && a.given_lattice)
    throw Error("--radius-lu, --box, --tau, --reynolds, --kernel, --sample-every and --offset are for --solver lbm");
  ShearRunSpec spec;
  spec.lattice = a.lattice;
  spec.integrator = a.integrator;
  spec.membrane = a.membrane;
  spec.skalak_c = a.skalak_c;
  spec.bim_quadrature = a.bim_quadrature;
  spec.folder = a.out;
  spec.solver = a.solver;
  spec.method = a.method;
  if (a.rings != 0) spec.method_options["rings"] = std::to_string(a.rings);
  add_option_assignments(spec.method_options, a.options);
  spec.mesh = a.mesh;
  spec.shape = a.shape;
  spec.G = a.G;
  spec.kappa_b_hat = a.kappa_b_hat;
  spec.kappa_b = a.kappa_b;
  spec.c0 = a.terms.c0;
  spec.ade_alpha = a.terms.ade_alpha;
  spec.ade_d = a.terms.ade_d;
  spec.ade_da0 = a.terms.ade_da0;
  spec.ade_area = a.terms.ade_area;
  spec.t_end = a.t_end;
  spec.snapshot_every = a.snapshot_every;
  spec.rtol = a.rtol;
  spec.atol = a.atol;
  spec.resume = a.resume;
  spec.overwrite = a.overwrite;
  spec.stop_after_steps = a.stop_after_steps;
  spec.max_steps = a.max_steps;
  ShearRunCallbacks callbacks;
  callbacks.on_note = note;
  callbacks.on_progress = [](const CapsuleProgress& p) {
    note(fmt::format("gamma t = {:7.4f} / {:g} ({:3.0f}%)  steps {:6d}  gamma dt {:.2e}  D {:.5f}  theta {:.4f}  "
                     "elapsed {:.0f} s  ETA {:.0f} s",
                     p.time, p.t_end, 100 * (p.time - p.t_start) / (p.t_end - p.t_start), p.steps, p.dt, p.D,
                     p.theta, p.elapsed_seconds, p.eta_seconds) +
         (p.mlups > 0 ? fmt::format("  {:.1f} MLUPS", p.mlups) : std::string()));
  };
  const ProcessWorld& world = process_world();
  if (world.size > 1) {
#ifdef BENDLAB_HAVE_MPI
    if (a.solver != "lbm")
      throw Error(fmt::format("{} processes: only --solver lbm runs in parallel (start the boundary-integral solver "
                              "without mpirun)", world.size));
    // The fluid in y-slabs over the ranks; rank 0 writes the run folder (docs/mpi.md).
    callbacks.make_lbm_solver = [](std::shared_ptr<const MembraneModel> m, const LbmSolverOptions& o) {
      return std::make_unique<parallel::MpiLbmCapsuleSolver>(std::move(m), o, MPI_COMM_WORLD);
    };
    callbacks.writes_files = world.rank == 0;
    note(fmt::format("lattice Boltzmann fluid in y-slabs over {} MPI ranks", world.size));
#endif
  }
  const CapsuleRunResult result = run_shear(spec, callbacks);
  if (world.rank != 0) return;
  if (!result.finished) {
    note(fmt::format("stopped after {} steps; continue with --resume", a.stop_after_steps));
    return;
  }
  std::cout << result.summary.dump() << std::endl;
  if (a.plot) plot(a);
}

const CommandRegistration shear_registration([](CLI::App& app) {
  auto args = std::make_shared<ShearArgs>();
  auto* cmd = app.add_subcommand("shear", "Simulate a capsule (neo-Hookean or Skalak membrane plus bending; "
                                          "initially a sphere, or a red blood cell or spheroid with --shape) in "
                                          "linear shear flow u = gamma z e_x at zero Reynolds number");
  cmd->add_option("--solver", args->solver,
                  "flow solver: bim (boundary integral method) or lbm (immersed-boundary lattice Boltzmann)")
      ->check(CLI::IsMember({"bim", "lbm"}))->capture_default_str();
  cmd->add_option("--method", args->method, "bending method: none, " + method_names_joined())
      ->check(CLI::IsMember(method_choices_with_none()))->capture_default_str();
  cmd->add_option("--rings", args->rings, "fitting support of E and ED (1, 2, 3)")->check(CLI::Range(1, 3));
  cmd->add_option("--option", args->options, "method option key=value, repeatable (the options of each method: "
                                             "bendlab methods), e.g. --option degree=6 for M; part of the run's "
                                             "identity on --resume");
  cmd->add_option("--mesh", args->mesh, "mt1:N or mt2:N (N triangles: 320, 1280, 5120, ...), inh:mt1 or inh:mt2 "
                                        "(320 triangles + 3 Rivara passes), or a mesh file (.off, .obj, .ply)")
      ->capture_default_str();
  cmd->add_option("--shape", args->shape.shape,
                  "initial shape: sphere (the paper's), rbc (the red blood cell of eq. (15)), oblate or prolate "
                  "(spheroid of --aspect); rbc and spheroids are scaled to the volume 4 pi/3 of the unit sphere and "
                  "are stress-free as they start unless --reference-shape says otherwise")
      ->check(CLI::IsMember(capsule_shape_names()))->capture_default_str();
  cmd->add_option("--aspect", args->shape.aspect,
                  "c/a of a spheroidal --shape (axis of symmetry over equatorial half-axis; oblate < 1, default "
                  "0.5; prolate > 1, default 2)");
  cmd->add_option("--tilt", args->shape.tilt_degrees,
                  "initial angle of the shape's axis of symmetry in the shear plane, in degrees from e_z towards e_x "
                  "(the sense the flow turns it), in [-180, 180]")
      ->capture_default_str();
  cmd->add_option("--reference-shape", args->shape.reference,
                  "stress-free shape of the elastic law: initial (the initial shape, the default), or sphere, rbc, "
                  "oblate, prolate mapped from the same mesh points and scaled to the initial shape's area")
      ->check(CLI::IsMember({"initial", "sphere", "rbc", "oblate", "prolate"}))->capture_default_str();
  cmd->add_option("--reference-aspect", args->shape.reference_aspect,
                  "c/a of a spheroidal --reference-shape (defaults as --aspect)");
  auto* membrane = cmd->add_option("--membrane", args->membrane,
                                   "in-plane elastic law: neo-hookean (the paper's, eq. 18) or skalak "
                                   "(Gs/4 (I1^2 + 2 I1 - 2 I2) + C Gs/4 I2^2 with Gs = kS/3)")
      ->check(CLI::IsMember({"neo-hookean", "skalak"}))->capture_default_str();
  cmd->add_option("--skalak-c", args->skalak_c,
                  "the Skalak law's C > -1/2 (area modulus Gs (1 + 2C), Poisson ratio C/(1 + C); --membrane skalak)")
      ->capture_default_str()->needs(membrane);
  cmd->add_option("--G", args->G, "dimensionless shear rate mu gamma R / kS (units R = mu = gamma = 1, kS = 1/G)")
      ->capture_default_str();
  auto* hat = cmd->add_option("--kappa-b-hat", args->kappa_b_hat,
                              "dimensionless bending modulus kappa_b_hat = kB / (R^2 kS) (default 0)");
  auto* dim = cmd->add_option("--kappa-b", args->kappa_b,
                              "dimensional bending modulus kB = kappa_b_hat / G (R = mu = gamma = 1)");
  hat->excludes(dim);
  add_membrane_term_options(cmd, args->terms, true,
                            " (dimensionless, in units of the capsule radius R = 1: c0 R, d / R, dA0 / R^2, A / R^2; "
                            "ADE's A defaults to the initial area; part of the run's identity on --resume)");
  cmd->add_option("--t-end", args->t_end, "end of the run in gamma t")->capture_default_str();
  auto tolerance = [args](const std::string&) { args->given_tolerance = true; };
  cmd->add_option("--integrator", args->integrator,
                  "time integrator of the BIM: cash-karp (the paper's) or rkc (Runge-Kutta-Chebyshev, stiff-stable)")
      ->check(CLI::IsMember({"cash-karp", "rkc"}))->capture_default_str()->each(tolerance);
  cmd->add_option("--bim-quadrature", args->bim_quadrature,
                  "regular quadrature of the BIM's single layer: all7 (the 7-point rule everywhere, the reference), "
                  "adaptive (7-point rule near each node, moment-corrected centroid rule far: 1.1 to 1.5 times "
                  "faster at 5120 triangles, velocities within about 1e-4 of all7) or tree (7-point rule near, "
                  "proxies of a cluster tree far: 1.5 to 1.8 times faster at 5120 triangles, slower at 1280, "
                  "velocities within about 2e-6 of all7) or tree-mixed (the tree with its sums in single "
                  "precision, summed in double: 3.7 to 3.9 times faster than all7 at 5120 triangles on one thread "
                  "with AVX-512, 1.6 times at 1280, within about 2e-6 of all7)")
      ->check(CLI::IsMember({"all7", "adaptive", "tree", "tree-mixed"}))->capture_default_str()->each(tolerance);
  auto lattice = [args](const std::string&) { args->given_lattice = true; };
  cmd->add_option("--rtol", args->rtol, "relative tolerance of the adaptive integrator (bim); above 1e-2 refused, "
                  "above 1e-4 warned (less accurate D, theta)")->capture_default_str()->each(tolerance);
  cmd->add_option("--atol", args->atol, "absolute tolerance of the adaptive integrator, in units of R (bim); above "
                  "1e-2 refused, above 1e-4 warned")->capture_default_str()->each(tolerance);
  cmd->add_option("--radius-lu", args->lattice.radius_lu, "capsule radius R in lattice units (lbm)")
      ->capture_default_str()->each(lattice);
  cmd->add_option("--box", args->lattice.box, "box edges in multiples of R: x,y,z (z: wall distance; lbm)")
      ->delimiter(',')->expected(3)->capture_default_str()->each(lattice);
  cmd->add_option("--tau", args->lattice.tau, "LBM relaxation time, > 1/2 (viscosity (tau - 1/2)/3; lbm)")
      ->capture_default_str()->each(lattice);
  cmd->add_option("--reynolds", args->lattice.reynolds,
                  "Reynolds number Re = R v / nu of the wall speed v, as in the paper (warns above its 0.3; "
                  "particle Re = gamma R^2 / nu is in summary.json; lbm)")
      ->capture_default_str()->each(lattice);
  cmd->add_option("--kernel", args->lattice.kernel, "immersed-boundary kernel: phi2 (ESPResSo's), phi3, phi4 (lbm)")
      ->check(CLI::IsMember({"phi2", "phi3", "phi4"}))->capture_default_str()->each(lattice);
  cmd->add_option("--sample-every", args->lattice.sample_every,
                  "gamma t between time-series rows, rounded to whole lattice steps (lbm)")
      ->capture_default_str()->each(lattice);
  cmd->add_option("--offset", args->lattice.offset,
                  "the capsule's starting centre in dx from the box centre (a cell corner), each component in "
                  "[-1, 1]: moves the capsule against the lattice nodes; a z offset carries it along x (lbm)")
      ->delimiter(',')->expected(3)->capture_default_str()->each(lattice);
  cmd->add_option("--snapshot-every", args->snapshot_every, "gamma t between .vtp snapshots and checkpoints")
      ->capture_default_str();
  auto* resume = cmd->add_flag("--resume", args->resume,
                               "continue the run in --out from its last checkpoint (--t-end must be later than the "
                               "checkpoint's time; equal to it, a run stopped before its summary is completed)");
  cmd->add_flag("--overwrite", args->overwrite,
                "start a new run in an --out that holds another run, removing that run's files (timeseries.csv, "
                "snapshots, checkpoint, summary, plot); without it such a folder is refused")
      ->excludes(resume);
  cmd->add_option("--stop-after-steps", args->stop_after_steps,
                  "stop after this many accepted steps (no summary; continue with --resume)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--max-steps", args->max_steps,
                  "fail the run (its last checkpoint kept) at its accepted step N + 1, counted over all its parts "
                  "(--resume included): a budget for a step size that collapses as a shape goes "
                  "unstable; 0: none (bim)")
      ->check(CLI::NonNegativeNumber)->capture_default_str();
  cmd->add_flag("!--no-plot", args->plot, "do not draw D_theta.png");
  cmd->add_option("--plot-script", args->plot_script,
                  "plot_shear.py to draw D_theta.png with (default: found beside the executable)");
  cmd->add_option("--out", args->out,
                  "output folder (created if missing; its parent must exist); locked while the run owns it, so a "
                  "second run into it is refused")
      ->required();
  cmd->callback([args] { shear(*args); });
});

}  // namespace
}  // namespace bendlab::cli
