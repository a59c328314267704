#pragma once
// A run of many cells in a tube, a channel or the shear box in physical units (shared/spec/CELLS_IN_CHANNELS.md;
// docs/conventions.md §6): the units and the lattice (flow/lbm/physical_units.hpp), the cell kind
// (cell_kind.hpp), the cells placed at a target hematocrit (suspension/placement.hpp), the
// cell-free flow and its flow rate Q0, and then the one run loop (capsule/capsule_run.hpp) with
// the suspension's solver (flow/lbm/lbm_suspension_solver.hpp) and recorder
// (suspension_recorder.hpp). `bendlab flow` and the Python module run it.
//
// The cell-free flow. Before the cells are added the lattice starts from the analytic Poiseuille
// flow (with its stress) and is stepped until its flow rate changes by less than 1e-9 relative
// over 100 steps (at most kMaxRelaxSteps): Q0 is that lattice's own flow rate, so that
// eta_app / eta = Q0 / Q compares two flows on the same lattice and the discretisation's error
// cancels; the cells then start in that flow. Everything is deterministic: a resume builds the
// same placement and Q0 and reads positions and fluid from the checkpoint.
//
// The shear box (geometry shear) starts from the walls' linear shear flow, a steady state of the
// lattice, and has no Q0 (its recorder reads the walls' stress). One cell (`cells` = 1) sits
// where `bendlab shear --solver lbm` puts its capsule, centred and unrotated, so that the shear
// command's lattice run is this run with one cell (docs/conventions.md §6); more cells are placed
// at random as in a tube.
#include <cstdint>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "bendlab/capsule/capsule_run.hpp"
#include "bendlab/flow/cell_kind.hpp"
#include "bendlab/flow/lbm/lbm_suspension_solver.hpp"
#include "bendlab/flow/lbm/physical_units.hpp"
#include "bendlab/flow/suspension_recorder.hpp"
#include "bendlab/suspension/placement.hpp"

namespace bendlab {

using SuspensionSolverFactory = std::function<std::unique_ptr<SuspensionSolver>(const SuspensionSolverOptions&)>;

struct FlowRunSpec {
  lbm::FlowUnitsInput units;           ///< geometry, sizes (um), dx, tau, plasma, driving
  CellKindSpec cell;                   ///< the cells' kind and membrane (physical units)
  std::optional<double> hematocrit;    ///< target tube hematocrit (0: no cells), or
  std::optional<int> cells;            ///< a number of cells
  std::uint64_t seed = 1;              ///< placement
  /// Repulsion (docs/conventions.md §6): cutoff in um (0: one dx) and the force at contact in N
  /// (0: G_s dx, the membrane's tension over one lattice spacing), between cells and at walls.
  double contact_cutoff_um = 0;
  double contact_force = 0;
  double sample_every = 1e-4;          ///< s between time-series rows
  double steady_from = 0.5;            ///< the steady window starts at steady_from t_end
  double slice_width_um = 1;           ///< the cell-free layer's slices along x
  /// Membrane forces every this many lattice steps, held in between (lbm::SuspensionOptions).
  int membrane_every = 1;

  /// The run's identity (checkpoint "arguments"): every field that changes its results.
  nlohmann::json to_json() const;
};

class FlowRun {
 public:
  static constexpr std::int64_t kMaxRelaxSteps = 200000;

  /// Validates (throws bendlab::Error naming the option: the units' refusals, a bad cell kind, a
  /// negative or unplaceable hematocrit with the best reached, a vessel narrower than a cell),
  /// places the cells and relaxes the cell-free flow. `note` receives progress lines.
  /// `make_solver` makes the solver from its options (default: LbmSuspensionSolver, one
  /// process; `mpirun bendlab flow` passes parallel::MpiSuspensionSolver's).
  FlowRun(const FlowRunSpec& spec, const std::function<void(const std::string&)>& note = nullptr,
          const SuspensionSolverFactory& make_solver = nullptr);

  /// Throws bendlab::Error naming --t-end where a run of `spec` to `t_end` would take less than
  /// one lattice step or more than a run can count (lbm::FlowUnits::checked_steps). Cheap: call it
  /// before the constructor's relaxation. run() checks it again.
  static void check_end(const FlowRunSpec& spec, double t_end);

  const FlowRunSpec& spec() const { return spec_; }
  const lbm::FlowUnits& units() const { return units_; }
  const CellKind& kind() const { return kind_; }
  const Placement& placement() const { return placement_; }
  const Vessel& vessel_um() const { return vessel_um_; }
  /// Q0, um^3/s, and the steps the relaxation took.
  double reference_flow_rate() const { return q0_; }
  std::int64_t relax_steps() const { return relax_steps_; }
  /// The lines a run prints about itself: the units, the capillary number, the cells.
  std::vector<std::string> describe() const;
  /// The mesh leak warning of the kind at this dx (cell_kind.hpp), if any.
  std::optional<std::string> warning() const;

  SuspensionSolver& solver() { return *solver_; }
  /// The lattice's fluid nodes (for MLUPS).
  double fluid_nodes() const;
  /// The run (capsule_run.hpp's options, t_end and snapshot_every in seconds); its arguments are
  /// spec().to_json() merged with options.arguments.
  CapsuleRunResult run(CapsuleRunOptions options);

 private:
  /// The placed cells, into the solver (after the fluid is set).
  void add_cells();

  FlowRunSpec spec_;
  lbm::FlowUnits units_;
  CellKind kind_;
  Vessel vessel_um_ = Vessel::box(1, 1, 1);
  Placement placement_;
  double q0_ = 0;
  std::int64_t relax_steps_ = 0;
  std::unique_ptr<SuspensionSolver> solver_;
};

}  // namespace bendlab
