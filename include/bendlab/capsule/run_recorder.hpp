#pragma once
// What a run records of its solver's accepted steps (capsule_run.hpp's run loop, run_solver):
// its time series, the running statistics of its summary, and the files those live in. The run
// loop owns the folder, the snapshots, the checkpoint and the step schedule; a recorder owns the
// measures. Two recorders exist:
//  - CapsuleRecorder (capsule_recorder.hpp): one capsule in shear; timeseries.csv with D, theta,
//    the energies and the motion angles; the steady statistics of table 4 and the motion;
//  - the suspension's (flow/suspension_recorder.hpp): many cells in a vessel; flow rate,
//    hematocrits, the cell-free layer and one row per cell.
//
// The recorder's state travels in checkpoint.json: state() returns top-level keys the checkpoint
// writes beside its own (capsule/checkpoint.hpp, CapsuleCheckpoint::recorder), and a resume hands
// them back to check_resume(). A resumed run must record exactly what the uninterrupted run would
// have: state() holds running sums at full precision, and the time series' kept rows are read back.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "bendlab/capsule/capsule_solver.hpp"

namespace bendlab {

struct CapsuleCheckpoint;

/// A recorder's figures for a progress line ("D", 0.31), in its own order.
using ProgressMeasures = std::vector<std::pair<std::string, double>>;

class RunRecorder {
 public:
  virtual ~RunRecorder() = default;

  /// Whether `name` is a file this recorder writes into the run folder (--overwrite removes it, a
  /// resume keeps it; a temporary the recorder's atomic writes can leave is recognised by the run).
  virtual bool is_output(const std::string& name) const = 0;

  /// A new run for t_end: creates the recorder's files in `folder` (when writes_files; the folder
  /// holds no file of a run then).
  virtual void start(const std::filesystem::path& folder, double t_end, bool writes_files) = 0;

  /// A resume to t_end from `saved` (validated as a checkpoint; its `recorder` keys are this
  /// recorder's): checks the kept rows of the recorder's files and its state against the
  /// checkpoint, before anything in the folder changes. Returns the largest step of the kept rows
  /// (0 when none) for CapsuleSolver::check_resumed_steps. Errors name `source` (the checkpoint)
  /// or the file and line.
  virtual double check_resume(const std::filesystem::path& folder, const CapsuleCheckpoint& saved, double t_end,
                              bool writes_files, const std::string& source) = 0;
  /// After check_resume and the solver's restore: truncates the recorder's files to the
  /// checkpoint's rows and restores its state. `note` receives what a user should know (a
  /// statistics window that moved with t_end).
  virtual void resume(const std::filesystem::path& folder, const CapsuleCheckpoint& saved, double t_end,
                      bool writes_files, const std::function<void(const std::string&)>& note) = 0;

  /// Records an accepted step (appending to the files when writing them).
  virtual void record(const AcceptedStep& step) = 0;
  /// Called with each snapshot of the bodies (snapshot_<tag>.vtp), before its checkpoint, on
  /// every process of the run: a recorder may write files of its own for it (a fluid slice) where
  /// the run writes files (the flag start() and resume() received), and its reads of a parallel
  /// solver are collective.
  virtual void snapshot(const std::filesystem::path& folder, const std::string& tag) {
    (void)folder;
    (void)tag;
  }
  /// The figures of the last recorded step for a progress line.
  virtual ProgressMeasures progress() const = 0;

  /// Top-level checkpoint keys (running sums at full precision); none may be a key of the
  /// checkpoint's own.
  virtual nlohmann::json state() const = 0;
  /// The recorder's fields of summary.json at t_end (results only, no clock), from its files as
  /// written where it reads them back; `positions` are the solver's at t_end.
  virtual nlohmann::json summary(const std::filesystem::path& folder, double t_end, const Points& positions) const = 0;
};

}  // namespace bendlab
