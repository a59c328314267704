#pragma once
// A run: drives a solver (capsule_solver.hpp) from its current state to t_end, keeps the run
// folder (run_folder.hpp) and lets a recorder (run_recorder.hpp) record every accepted step. One
// loop for every solver and every recorder: run_capsule() is the run of one capsule (its recorder
// CapsuleRecorder, capsule_recorder.hpp); a suspension of many cells is a run with its own
// recorder (flow/suspension_run.hpp). For a capsule the folder holds:
//
//   timeseries.csv   one row per accepted step (time_series.hpp), append-only, flushed per row
//   snapshot_NNNNN.vtp + shapes.pvd   the shape every snapshot_every (and at t_end)
//   checkpoint.json  the state at the last snapshot (checkpoint.hpp), for resume
//   summary.json     the arguments, the steady statistics (steady_statistics.hpp), counters,
//                    volumes and the motion (motion.hpp: tumbling, swinging, periods, from
//                    timeseries.csv as written): results only, no clock
//   timing.json      wall_seconds of all parts, wall_seconds_last_part, resumed
//
// A resumed run (options.resume) validates checkpoint.json as a whole, checks that its arguments
// equal options.arguments, truncates timeseries.csv to the checkpoint's rows (atomic rewrite),
// restores the solver and continues; its summary.json then equals the uninterrupted run's exactly
// (the wall time is in timing.json, which does not). If t_end changed so
// that the steady window moved, the window's sums are recomputed from timeseries.csv (to the
// precision of the file: dt has 6 digits, so about 1e-6 relative) and a note says so.
//
// Every write is checked: a failed write throws bendlab::Error naming the file, and the last
// complete checkpoint stays in place. Nothing here prints: progress and notes go to callbacks.
//
// The folder is locked (core/folder_lock.hpp) while a run owns it: a second run into it is
// refused at once. A new run into a folder holding another run is refused unless
// options.overwrite. A resume trusts nothing it reads back: the checkpoint's snapshot list must
// name snapshot_00000.vtp, snapshot_00001.vtp, ... up to the checkpoint's time, all present; its
// side files must be the solver's own names; the kept rows of timeseries.csv are parsed like new
// ones, their steps must be positive and add up to their times, and the last must be at the
// checkpoint's time (so "steps" equals the row count). Temporary files an interrupted write left
// in the folder are removed.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>

#include "bendlab/capsule/capsule_recorder.hpp"
#include "bendlab/capsule/capsule_shape.hpp"
#include "bendlab/capsule/capsule_solver.hpp"
#include "bendlab/capsule/run_recorder.hpp"
#include "bendlab/capsule/time_series.hpp"

namespace bendlab {

struct CapsuleProgress {
  double time = 0, t_start = 0, t_end = 0;  ///< gamma t now, at the start of this part, at the end
  double dt = 0;                            ///< the last step
  double D = 0, theta = 0;                  ///< a capsule's (CapsuleRecorder); NaN for other recorders
  ProgressMeasures measures;                ///< the recorder's figures of the last step
  std::int64_t steps = 0;                   ///< accepted steps of the whole run
  double elapsed_seconds = 0;               ///< wall time of this part
  double eta_seconds = 0;                   ///< estimated wall time to t_end
  bool final = false;                       ///< the report at t_end
  double mlups = 0;                         ///< lattice node updates per second (lattice solvers; else 0)
};

struct CapsuleRunOptions {
  std::filesystem::path folder;  ///< run folder (created if missing; its parent must exist)
  double t_end = 10;             ///< gamma t
  double snapshot_every = 0.5;   ///< gamma t between snapshots and checkpoints
  bool resume = false;           ///< continue from folder/checkpoint.json
  /// A new run (not resume) into a folder that holds files of another run: false refuses it,
  /// true removes that run's files (run_file_name) first. Files of other names are never touched.
  bool overwrite = false;
  /// The run's identity: must be equal (numbers to 1e-12 relative) when resuming; copied into
  /// checkpoint.json and summary.json.
  nlohmann::json arguments = nlohmann::json::object();
  /// Further fields of summary.json that may change between parts (tolerances, mesh label, ...).
  nlohmann::json summary_fields = nlohmann::json::object();
  /// Stop (without a summary) after this many accepted steps of this part; 0: never. The run can
  /// then be resumed from its last checkpoint (how tests interrupt a run).
  std::int64_t stop_after_steps = 0;
  /// The run fails (an Error naming the budget, the last checkpoint kept) at its accepted step
  /// max_steps + 1, counted over all its parts; 0: no budget. A step size that
  /// collapses without reaching dt_min (a shape going unstable) would otherwise crawl for days.
  std::int64_t max_steps = 0;
  /// Asked after every accepted step; true stops the run as stop_after_steps does (no summary;
  /// resumable from the last checkpoint). How an interactive caller (Ctrl-C in Python) stops.
  std::function<bool()> should_stop;
  /// How the run's messages name its time: "gamma t" (a shear run's unit) or "t (s)" (a flow
  /// run's seconds).
  std::string time_name = "gamma t";
  double progress_interval_seconds = 2;  ///< wall time between progress reports
  /// false on every process of a parallel run but the first (MPI rank 0): the process steps,
  /// checkpoints (solver.save_state is collective) and resumes with the others, but writes no
  /// file of its own (no folder, time series, snapshot, checkpoint.json or summary.json), and
  /// the result's summary is left empty.
  bool writes_files = true;
  std::function<void(const CapsuleProgress&)> on_progress;
  std::function<void(const std::string&)> on_note;
  /// Lines for on_note once the run has passed every check of its folder and checkpoint, before
  /// its first step (what the run uses, said only of a run that goes ahead).
  std::vector<std::string> start_notes;
};

struct CapsuleRunResult {
  bool finished = false;   ///< reached t_end (false: stopped by stop_after_steps)
  nlohmann::json summary;  ///< summary.json's content (when finished)
  double wall_seconds = 0; ///< wall time of all parts of the run (timing.json; when finished)
};

/// Runs `solver` as described above, `recorder` recording its steps. Throws bendlab::Error
/// (before any file changes for bad options or a refused checkpoint).
CapsuleRunResult run_solver(CapsuleSolver& solver, RunRecorder& recorder, const CapsuleRunOptions& options);

/// The run of one capsule: run_solver with a CapsuleRecorder of the solver's membrane.
CapsuleRunResult run_capsule(CapsuleSolver& solver, const CapsuleRunOptions& options);

/// Whether `name` is a file a capsule run writes into its folder (with `solver`'s side files), or
/// a temporary the run can have made for one (run_folder.hpp): the files --overwrite removes.
/// Other names are never the run's.
bool is_run_file(const std::string& name, const CapsuleSolver& solver);

/// Whether two argument sets are equal (same keys; numbers to 1e-12 relative); otherwise the first
/// difference in words ("G is 0.2 here but 0.1 in the checkpoint").
std::string compare_arguments(const nlohmann::json& here, const nlohmann::json& saved);

}  // namespace bendlab
