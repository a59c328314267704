#pragma once
// The paper's section 4 run, as one library call: an initially spherical capsule (or, beyond the
// paper, a red blood cell or a spheroid with a reference shape of its own, capsule/initial_shape.hpp) (elastic law
// (neo-Hookean, or Skalak beyond the paper) +
// bending method) in the shear flow u = gamma z e_x, in the units of capsule/shear_units.hpp
// (R = mu = gamma = 1, kS = 1/G, kB = kappa_b_hat / G), solved by a flow solver behind
// CapsuleSolver and kept by run_capsule (capsule/capsule_run.hpp: time series, snapshots,
// checkpoint, summary). `bendlab shear` and the Python module both call it, so a run started by
// one can be resumed by the other.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "bendlab/bending/bending_method.hpp"
#include "bendlab/capsule/capsule_run.hpp"
#include "bendlab/capsule/initial_shape.hpp"
#include "bendlab/flow/lbm/lbm_capsule_solver.hpp"

namespace bendlab {

/// The lattice of --solver lbm (paper section 4.3.2, flow/lbm/parameters.hpp).
struct LatticeRunSpec {
  double radius_lu = 6;                ///< capsule radius R in lattice units
  std::vector<double> box = {8, 8, 10};  ///< box edges in multiples of R (z: the wall distance)
  double tau = 1;                      ///< relaxation time, > 1/2
  double reynolds = 0.2;               ///< Re = R v / nu of the wall speed (the paper's; warned above 0.3)
  std::string kernel = "phi2";         ///< immersed-boundary kernel: phi2, phi3, phi4
  double sample_every = 1e-3;          ///< gamma t between time-series rows
  /// The capsule's starting centroid in dx from the box centre, each component in [-1, 1]
  /// (LbmSolverOptions::offset); recorded in the run's arguments only when not zero.
  std::vector<double> offset = {0, 0, 0};
};

struct ShearRunSpec {
  std::filesystem::path folder;        ///< run folder (created if missing; its parent must exist)
  std::string solver = "bim";          ///< flow solver: "bim" or "lbm"
  LatticeRunSpec lattice;              ///< used by "lbm"
  std::string method = "none";         ///< bending method (registry name) or "none"
  MethodOptions method_options;        ///< options of the method, as on a command line
  std::string membrane = "neo-hookean";  ///< in-plane elastic law: "neo-hookean" or "skalak" (elasticity/)
  double skalak_c = 1;                 ///< the Skalak law's C (> -1/2); only with membrane = "skalak"
  std::string mesh = "mt1:1280";       ///< mesh_spec.hpp: mt1:N, mt2:N, octa:N, inh:mt1, inh:mt2 or a file
  /// The initial shape, its tilt and the stress-free reference shape (capsule/initial_shape.hpp);
  /// the default is the paper's sphere.
  CapsuleShapeSpec shape;
  double G = 0.1;                      ///< mu gamma R / kS
  std::optional<double> kappa_b_hat;   ///< kB / (R^2 kS) (exclusive with kappa_b)
  std::optional<double> kappa_b;       ///< dimensional kB
  /// Spontaneous curvature and ADE (docs/conventions.md §5) in units of R (R = 1 in these runs):
  /// c0 R, alpha, d / R, dA0 / R^2, A / R^2. ade_area: none = the area of the initial mesh.
  double c0 = 0, ade_alpha = 0, ade_d = 0, ade_da0 = 0;
  std::optional<double> ade_area;
  double t_end = 10;                   ///< gamma t
  double snapshot_every = 0.5;         ///< gamma t between snapshots and checkpoints
  std::string integrator = "cash-karp";  ///< BIM time stepping: "cash-karp" or "rkc" (stiff-stable, integrate/rkc.hpp)
  std::string bim_quadrature = "all7";  ///< the BIM single layer's regular quadrature: "all7" (reference), "adaptive", "tree" or "tree-mixed" (stokes_single_layer.hpp)
  double rtol = 1e-7, atol = 1e-6;     ///< the BIM integrator's tolerances (atol in units of R)
  bool resume = false;                 ///< continue from folder/checkpoint.json
  bool overwrite = false;              ///< a new run may replace another run's files in folder (CapsuleRunOptions)
  std::int64_t stop_after_steps = 0;   ///< stop (resumable) after this many steps; 0: never
  std::int64_t max_steps = 0;          ///< fail after this many accepted steps in all parts; 0: no budget
};

struct ShearRunCallbacks {
  std::function<void(const CapsuleProgress&)> on_progress;
  std::function<void(const std::string&)> on_note;
  std::function<bool()> should_stop;  ///< true stops the run (resumable from its last checkpoint)
  double progress_interval_seconds = 2;
  /// Builds the --solver lbm solver in place of LbmCapsuleSolver (a parallel run's: the command
  /// line's MPI solver, parallel/mpi_lbm_capsule_solver.hpp). Same options, same checkpoints.
  std::function<std::unique_ptr<CapsuleSolver>(std::shared_ptr<const MembraneModel>, const LbmSolverOptions&)>
      make_lbm_solver;
  /// false on the processes of a parallel run other than the first (CapsuleRunOptions::writes_files).
  bool writes_files = true;
};

/// Checks every parameter (before any file is touched), builds the mesh, the membrane model and
/// the solver, and runs. Throws bendlab::Error with a one-line message naming the option.
CapsuleRunResult run_shear(const ShearRunSpec& spec, const ShearRunCallbacks& callbacks = {});

}  // namespace bendlab
