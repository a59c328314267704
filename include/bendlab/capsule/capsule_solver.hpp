#pragma once
// What a flow solver offers to a run (capsule_run.hpp). The run owns the files (snapshots,
// checkpoint, summary) and its recorder (run_recorder.hpp) the time series and the statistics;
// the solver owns the physics and its own state. A solver moves bodies: one capsule, or the many
// cells of a suspension (flow/lbm/lbm_suspension_solver.hpp); positions() holds all their
// vertices, body after body. Two kinds of capsule solver fit behind it:
//  - the boundary integral method (flow/bim/bim_capsule_solver.hpp): node velocity = function of
//    the positions, advanced by an adaptive Integrator; its extra state is the proposed next step;
//  - a lattice Boltzmann solver: fixed steps, explicit Euler for the nodes, a fluid whose state
//    evolves; its extra state is a binary side file of the fluid.
// Both take their membrane forces from a MembraneModel.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "bendlab/core/types.hpp"
#include "bendlab/membrane/membrane_model.hpp"

namespace bendlab {

/// Cumulative counts of a solver since the start of the run (restored on resume).
struct SolverCounters {
  std::int64_t rejected_steps = 0;        ///< steps an adaptive controller refused (0 for fixed steps)
  std::int64_t velocity_evaluations = 0;  ///< evaluations of the node velocity (BIM: of eq. (23))
};

/// What the run sees after each accepted step (and after any projection or rescaling).
struct AcceptedStep {
  double time = 0;                     ///< gamma t after the step
  double dt = 0;                       ///< the step just taken
  const Points* positions = nullptr;   ///< N x 3, valid during the callback only
};

/// A body a solver moves: its membrane (reference state, moduli, topology) and its rows of the
/// solver's positions(): [first_row, first_row + membrane->num_vertices()).
struct SolverBody {
  const MembraneModel* membrane = nullptr;
  Eigen::Index first_row = 0;
};

/// The solver-specific part of a checkpoint: JSON fields, plus side files the solver wrote into
/// the run folder (names relative to it). The run deletes the side files of an older checkpoint
/// once a newer checkpoint.json has been committed, so a solver must give its side files names
/// unique to `tag` (e.g. "lbm_fluid_<tag>.bin") and write them whole (AtomicFile). restore_state
/// gets `fields` only, so a solver also names its side files there.
struct SolverState {
  nlohmann::json fields = nlohmann::json::object();
  std::vector<std::string> side_files;
};

class CapsuleSolver {
 public:
  /// Returns false to stop the run after this step.
  using OnStep = std::function<bool(const AcceptedStep&)>;

  virtual ~CapsuleSolver() = default;
  /// "bim", "lbm", ...
  virtual std::string name() const = 0;
  /// The membrane whose nodes the solver moves (reference state, moduli, energies); a solver of
  /// several bodies returns its first body's.
  virtual const MembraneModel& membrane() const = 0;
  /// Every body, in the order of positions()' rows: a capsule solver's one membrane.
  virtual std::vector<SolverBody> bodies() const { return {{&membrane(), 0}}; }

  /// Current node positions (N x 3: every body's) and time (the run's unit: gamma t, or seconds).
  virtual const Points& positions() const = 0;
  virtual double time() const = 0;

  /// Advances until time() >= t_end (adaptive solvers land on t_end exactly), calling on_step
  /// after each accepted step. Returns false if on_step stopped it. Throws bendlab::Error if the
  /// solver fails (e.g. the step size collapses).
  virtual bool advance(double t_end, const OnStep& on_step) = 0;

  virtual SolverCounters counters() const = 0;
  /// Fields the solver adds to a run's summary.json (e.g. its integrator's statistics); they must
  /// survive a resume, so a resumed run writes the same values as the uninterrupted one.
  virtual nlohmann::json summary() const { return nlohmann::json::object(); }

  /// The solver's own state at the current time, beyond positions and time (which the run saves).
  /// `folder` is the run folder, `tag` a name unique to this checkpoint for side files.
  virtual SolverState save_state(const std::filesystem::path& folder, const std::string& tag) const = 0;
  /// Restores positions, time, counters and the solver's own state (as save_state returned it),
  /// validating it; errors name `source` (the checkpoint file) and the offending key.
  virtual void restore_state(const Points& positions, double time, const SolverCounters& counters,
                             const nlohmann::json& fields, const std::filesystem::path& folder,
                             const std::string& source) = 0;
  /// Whether `name` is a side file this solver writes (save_state): a checkpoint naming any other
  /// file is refused, and the run deletes no file of another name.
  virtual bool is_side_file(const std::string& name) const {
    (void)name;
    return false;
  }
  /// Called after restore_state on a resume with the largest step of the kept time-series rows
  /// (0 when none): throws bendlab::Error naming `source` if the restored state is inconsistent
  /// with the steps taken (e.g. a proposed step no controller would have proposed).
  virtual void check_resumed_steps(double largest_step, const std::string& source) const {
    (void)largest_step;
    (void)source;
  }
};

}  // namespace bendlab
