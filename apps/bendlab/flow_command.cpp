// bendlab flow: red blood cells (or other cell kinds) in a tube, a slit channel or the shear box,
// periodic along the flow, on the lattice Boltzmann solver with the immersed boundary, in physical units
// (shared/spec/CELLS_IN_CHANNELS.md; docs/conventions.md §6). Argument parsing only: the run is
// FlowRun (bendlab/flow/flow_run.hpp), whose folder belongs to the one run loop
// (bendlab/capsule/capsule_run.hpp) with the suspension's recorder
// (bendlab/flow/suspension_recorder.hpp).
#include <fmt/format.h>

#include <iostream>
#include <optional>

#include "bendlab/flow/flow_run.hpp"
#include "command.hpp"
#include "method_cli.hpp"

#ifdef BENDLAB_HAVE_MPI
#include "bendlab/parallel/mpi_suspension_solver.hpp"
#endif

namespace bendlab::cli {
namespace {

struct FlowArgs {
  std::string geometry = "tube", out;
  std::optional<std::string> bending_net_force;  // unset: remove where there is a bending force
  std::optional<double> diameter, height, width, pseudo_shear_rate, body_force, shear_rate, hematocrit;
  std::optional<int> cells;
  double length = 0;
  double contact_force_pn = 0;
  double t_end = 0.01, snapshot_every = 0.001;
  std::vector<std::string> options;
  std::int64_t stop_after_steps = 0;
  bool resume = false, overwrite = false;
  FlowRunSpec spec;
};

void flow(FlowArgs& a) {
  FlowRunSpec& s = a.spec;
  const bool tube = a.geometry == "tube";
  s.units.geometry = tube                     ? lbm::FlowGeometry::Tube
                     : a.geometry == "shear" ? lbm::FlowGeometry::Shear
                                             : lbm::FlowGeometry::Channel;
  if (tube) {
    if (!a.diameter) throw Error("--diameter (um) is required for --geometry tube");
    if (a.height || a.width) throw Error("--height and --width are for --geometry channel (a tube takes --diameter)");
    s.units.diameter_um = *a.diameter;
  } else {
    if (!a.height || !a.width) throw Error(fmt::format("--height and --width (um) are required for --geometry {}", a.geometry));
    if (a.diameter) throw Error(fmt::format("--diameter is for --geometry tube (a {} takes --height and --width)", a.geometry));
    s.units.height_um = *a.height;
    s.units.width_um = *a.width;
  }
  if (!(a.length > 0)) throw Error("--length (um, the periodic extent along the flow) is required and positive");
  s.units.length_um = a.length;
  s.units.pseudo_shear_rate = a.pseudo_shear_rate;
  s.units.body_force = a.body_force;
  s.units.shear_rate = a.shear_rate;
  s.hematocrit = a.hematocrit;
  s.cells = a.cells;
  if (!a.hematocrit && !a.cells) throw Error("give --hematocrit (tube hematocrit, 0: plain Poiseuille flow) or --cells");
  if (!(a.contact_force_pn >= 0) || !std::isfinite(a.contact_force_pn))
    throw Error(fmt::format("--contact-force {} pN must be >= 0 (0: the default G_s dx)", a.contact_force_pn));
  s.contact_force = a.contact_force_pn * 1e-12;
  s.cell.method_options = a.options;
  // Momentum-conserving by default (docs/conventions.md §6): the net force and torque of the
  // bending force are taken off each cell unless --bending-net-force keep.
  s.cell.choose_bending_net_force(a.bending_net_force);
  FlowRun::check_end(s, a.t_end);

  // Under mpirun: the fluid in y-slabs and each cell owned by one rank; rank 0 writes the run
  // folder (docs/mpi.md, "Many cells").
  const ProcessWorld& world = process_world();
  SuspensionSolverFactory make_solver;
  if (world.size > 1) {
#ifdef BENDLAB_HAVE_MPI
    if (s.units.geometry == lbm::FlowGeometry::Shear)
      throw Error(fmt::format("{} processes: --geometry shear runs on one process (start it without mpirun); tubes and "
                              "channels run in parallel", world.size));
    make_solver = [](const SuspensionSolverOptions& o) {
      return std::make_unique<parallel::MpiSuspensionSolver>(o, MPI_COMM_WORLD);
    };
    note(fmt::format("lattice Boltzmann fluid in y-slabs over {} MPI ranks, each cell owned by one", world.size));
#endif
  }
  FlowRun run(s, note, make_solver);
  for (const std::string& line : run.describe()) note(line);
  if (const auto w = run.warning()) note(*w);  // the warning names itself
  CapsuleRunOptions o;
  o.folder = a.out;
  o.t_end = a.t_end;
  o.snapshot_every = a.snapshot_every;
  o.resume = a.resume;
  o.overwrite = a.overwrite;
  o.stop_after_steps = a.stop_after_steps;
  o.on_note = note;
  if (s.cell.has_bending())
    o.start_notes.push_back(
        s.cell.bending_without_net_force
            ? fmt::format("bending force: Method {}'s, its net force and torque removed on each cell{}", s.cell.method,
                          a.bending_net_force ? "" : " (the default; --bending-net-force keep keeps them)")
            : fmt::format("bending force: Method {}'s as the method gives it, net force and torque kept "
                          "(--bending-net-force keep)",
                          s.cell.method));
  o.writes_files = world.rank == 0;
  const double dt = run.units().dt;
  const double nodes = run.fluid_nodes();
  o.on_progress = [dt, nodes](const CapsuleProgress& p) {
    std::string measures;
    for (const auto& [name, value] : p.measures) measures += fmt::format("  {} {:.4g}", name, value);
    const double steps = (p.time - p.t_start) / dt;
    note(fmt::format("t = {:.4g} / {:g} s ({:3.0f}%){}  elapsed {:.0f} s  ETA {:.0f} s  {:.1f} MLUPS", p.time, p.t_end,
                     100 * (p.time - p.t_start) / (p.t_end - p.t_start), measures, p.elapsed_seconds, p.eta_seconds,
                     p.elapsed_seconds > 0 ? steps * nodes / p.elapsed_seconds * 1e-6 : 0.0));
  };
  const CapsuleRunResult result = run.run(o);
  if (world.rank != 0) return;
  if (!result.finished) {
    note(fmt::format("stopped after {} reports; continue with --resume", a.stop_after_steps));
    return;
  }
  std::cout << result.summary.dump() << std::endl;
}

const CommandRegistration flow_registration([](CLI::App& app) {
  auto args = std::make_shared<FlowArgs>();
  FlowRunSpec& s = args->spec;
  auto* cmd = app.add_subcommand(
      "flow", "Simulate cells (red blood cells by default) in a tube, a slit channel or a shear box, periodic along "
              "the flow, with the immersed-boundary lattice Boltzmann method in physical units: apparent viscosity, "
              "hematocrits, cell-free layer, profiles");
  cmd->add_option("--geometry", args->geometry, "tube (a circular tube), channel (plane walls at z = -+H/2, "
                                                "periodic in y over --width) or shear (walls at z = -+H/2 moving "
                                                "with -+gamma H / 2 along x: the box of shear --solver lbm; one cell "
                                                "sits at its centre)")
      ->check(CLI::IsMember({"tube", "channel", "shear"}))->capture_default_str();
  cmd->add_option("--diameter", args->diameter, "tube diameter D, um (whole dx not needed: the wall is interpolated)");
  cmd->add_option("--height", args->height, "channel or shear box height H (wall distance), um, a whole number of dx");
  cmd->add_option("--width", args->width, "channel or shear box width (periodic, across the flow), um, a whole number of dx");
  cmd->add_option("--length", args->length, "periodic length along the flow, um, a whole number of dx")->required();
  cmd->add_option("--dx", s.units.dx_um, "lattice spacing, um")->capture_default_str();
  cmd->add_option("--tau", s.units.tau, "LBM relaxation time, > 1/2: sets dt = (tau - 1/2) dx^2 / (3 nu)")
      ->capture_default_str();
  auto* rate = cmd->add_option("--pseudo-shear-rate", args->pseudo_shear_rate,
                               "driving as the pseudo-shear rate v / D (v / H) of the cell-free flow, 1/s (v its "
                               "mean velocity, Pries' measure)");
  auto* force = cmd->add_option("--body-force", args->body_force, "driving as a body force density along x, N/m^3");
  auto* shear_rate = cmd->add_option("--shear-rate", args->shear_rate,
                                     "the shear box's driving: its walls' shear rate gamma, 1/s");
  rate->excludes(force);
  shear_rate->excludes(rate)->excludes(force);
  cmd->add_option("--plasma-viscosity", s.units.plasma.viscosity, "Pa s")->capture_default_str();
  cmd->add_option("--plasma-density", s.units.plasma.density, "kg/m^3")->capture_default_str();
  cmd->add_option("--time-scale", s.units.time_scale,
                  "time scaling S >= 1: the lattice works with S times the plasma density, which in Stokes flow only "
                  "raises the Reynolds number, so dt is S times longer and a run takes S times fewer steps; refused "
                  "where Re would exceed 0.85, the measured bound (docs/conventions.md §6)")
      ->capture_default_str();
  auto* hct = cmd->add_option("--hematocrit", args->hematocrit,
                              "target tube hematocrit H_T in [0, 1) (0: plain Poiseuille flow; in the shear box the "
                              "cells' volume fraction); placement reports what it reached and refuses what it cannot place");
  auto* count = cmd->add_option("--cells", args->cells, "a number of cells instead of --hematocrit");
  hct->excludes(count);
  cmd->add_option("--seed", s.seed, "placement seed")->capture_default_str();
  cmd->add_option("--cell", s.cell.shape, "cell kind: rbc (eq. (15) of the paper) or sphere")
      ->check(CLI::IsMember({"rbc", "sphere"}))->capture_default_str();
  cmd->add_option("--cell-radius", s.cell.radius_um, "cell radius R, um (rbc: the large half-axis)")
      ->capture_default_str();
  cmd->add_option("--mesh", s.cell.mesh, "cell mesh: mt1:N or mt2:N (N triangles) or a mesh file")
      ->capture_default_str();
  cmd->add_option("--method", s.cell.method, "bending method: " + method_names_joined())
      ->check(CLI::IsMember(method_choices_with_none()))->capture_default_str();
  cmd->add_option("--option", args->options, "method option key=value, repeatable (bendlab methods)");
  cmd->add_option("--bending-net-force", args->bending_net_force,
                  "remove (the default where there is a bending force): take the bending force's net force and "
                  "torque off each cell, so that bending conserves momentum (the discrete forces of Methods C, D, "
                  "E, ED, M and S have some; A, B and J have none); keep: the bending method's force as it is")
      ->check(CLI::IsMember({"keep", "remove"}));
  cmd->add_option("--membrane", s.cell.elastic_law, "in-plane elastic law: skalak or neo-hookean")
      ->check(CLI::IsMember({"skalak", "neo-hookean"}))->capture_default_str();
  cmd->add_option("--shear-modulus", s.cell.shear_modulus, "membrane shear modulus G_s, N/m")->capture_default_str();
  cmd->add_option("--skalak-c", s.cell.skalak_c, "the Skalak law's C (area modulus G_s (1 + 2C))")
      ->capture_default_str();
  cmd->add_option("--bending-modulus", s.cell.bending_modulus, "bending modulus kappa_B, J")->capture_default_str();
  cmd->add_option("--volume-ratio", s.cell.volume_modulus_ratio,
                  "kappa_V / kappa_S of the volume force (0: none)")->capture_default_str();
  cmd->add_option("--contact-cutoff", s.contact_cutoff_um,
                  "repulsion cutoff between cells and at walls, um (0: one dx)")->capture_default_str();
  cmd->add_option("--contact-force", args->contact_force_pn,
                  "repulsion force at contact, pN (0: G_s dx, the membrane tension over one dx)")
      ->capture_default_str();
  cmd->add_option("--membrane-every", s.membrane_every,
                  "compute the cells' membrane forces (elasticity, bending, volume) every N lattice steps and hold "
                  "them in between, HemoCell's time-scale separation (its stepMaterialEvery); contact forces and "
                  "the cells' motion stay every step, reports fall on multiples of N. Its error: "
                  "docs/results/suspension_performance.md. One process only")
      ->check(CLI::PositiveNumber)->capture_default_str();
  cmd->add_option("--t-end", args->t_end, "end of the run, s")->capture_default_str();
  cmd->add_option("--sample-every", s.sample_every, "s between time-series rows (whole lattice steps)")
      ->capture_default_str();
  cmd->add_option("--snapshot-every", args->snapshot_every, "s between .vtp snapshots of all cells and checkpoints")
      ->capture_default_str();
  cmd->add_option("--steady-from", s.steady_from,
                  "the steady window of the summary's means starts at this fraction of --t-end")
      ->capture_default_str();
  cmd->add_option("--slice-width", s.slice_width_um, "slices along x of the cell-free layer, um")
      ->capture_default_str();
  auto* resume = cmd->add_flag("--resume", args->resume,
                               "continue the run in --out from its last checkpoint (--t-end later than the "
                               "checkpoint's, or equal to complete a run stopped before its summary)");
  cmd->add_flag("--overwrite", args->overwrite,
                "start a new run in an --out that holds another run, removing that run's files")
      ->excludes(resume);
  cmd->add_option("--stop-after-steps", args->stop_after_steps,
                  "stop after this many time-series rows (no summary; continue with --resume)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--out", args->out,
                  "output folder (created if missing; its parent must exist); locked while the run owns it")
      ->required();
  cmd->callback([args] { flow(*args); });
});

}  // namespace
}  // namespace bendlab::cli
