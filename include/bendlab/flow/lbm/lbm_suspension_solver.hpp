#pragma once
// Many cells in a lattice Boltzmann fluid (lbm_suspension.hpp) behind the solver interface of a
// run (capsule/capsule_solver.hpp): each cell is a body, and the run loop (capsule_run.hpp) keeps
// the folder, the snapshots of all cells, the checkpoint and resume, as for one capsule.
//
// Units. The suspension steps in lattice units; the run sees physical ones: positions() in um
// (X dx), time() in seconds (lattice steps dt). The step is reported to the run every
// sample_every seconds (rounded to whole lattice steps, at least 1) and at the step that reaches
// t_end; AcceptedStep::dt is the time since the report before.
//
// Blow-up. Vertex positions are checked every step (LbmSuspension::step) and the fluid's density
// every kFluidCheckSteps steps and before every checkpoint: a non-finite or non-positive density
// throws bendlab::Error naming the lattice node and step, before the step is reported, so the
// run's last checkpoint stays the last good state.
//
// Checkpoint state: flow/lbm/fluid_state.hpp (the fluid file, the lattice step and every vertex
// in dx), so a resumed run repeats the uninterrupted one bit for bit.
#include <cstdint>
#include <filesystem>
#include <memory>

#include "bendlab/capsule/capsule_solver.hpp"
#include "bendlab/flow/lbm/lbm_suspension.hpp"

namespace bendlab {

struct SuspensionSolverOptions {
  lbm::SuspensionOptions suspension;
  double dx_um = 0;         ///< um per lattice spacing
  double dt_seconds = 0;    ///< seconds per lattice step
  double sample_every = 0;  ///< seconds between reported steps (>= one lattice step)
};

class LbmSuspensionSolver final : public CapsuleSolver {
 public:
  static constexpr std::int64_t kFluidCheckSteps = 1000;

  /// An empty suspension at rest at time 0; add cells and set the fluid through suspension()
  /// before the run starts. Throws bendlab::Error for non-positive or non-finite units or
  /// sample_every, and as LbmSuspension does.
  explicit LbmSuspensionSolver(SuspensionSolverOptions options);

  std::string name() const override { return "lbm-suspension"; }
  /// The first cell's membrane (throws without cells).
  const MembraneModel& membrane() const override;
  std::vector<SolverBody> bodies() const override;
  /// Every vertex, cell after cell, in um.
  const Points& positions() const override { return x_; }
  double time() const override { return static_cast<double>(suspension_.steps()) * options_.dt_seconds; }
  bool advance(double t_end, const OnStep& on_step) override;
  SolverCounters counters() const override { return counters_; }
  SolverState save_state(const std::filesystem::path& folder, const std::string& tag) const override;
  void restore_state(const Points& positions, double time, const SolverCounters& counters,
                     const nlohmann::json& fields, const std::filesystem::path& folder,
                     const std::string& source) override;
  bool is_side_file(const std::string& name) const override;

  /// Adds a cell at positions X in um (lattice units inside); returns its index.
  int add_cell(std::shared_ptr<const MembraneModel> lattice_membrane, const Points& X_um);
  /// The suspension, for its fluid and cells (a caller that changes it before the run starts calls
  /// sync_positions afterwards).
  lbm::LbmSuspension& suspension() { return suspension_; }
  const lbm::LbmSuspension& suspension() const { return suspension_; }
  const SuspensionSolverOptions& options() const { return options_; }
  /// Lattice steps between reports.
  std::int64_t sample_steps() const { return sample_steps_; }
  /// positions() from the suspension's lattice positions.
  void sync_positions();

 private:
  void check_fluid() const;

  SuspensionSolverOptions options_;
  lbm::LbmSuspension suspension_;
  std::int64_t sample_steps_ = 1;
  Points x_;  // um
  SolverCounters counters_;
  std::int64_t last_fluid_check_ = 0;
};

}  // namespace bendlab
