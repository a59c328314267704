#pragma once
// checkpoint.json of a capsule run: everything a resumed run needs to end exactly as the
// uninterrupted run would have, written whole (AtomicFile) at every snapshot.
//
//   {"format": "bendlab capsule checkpoint", "version": 2,
//    "arguments": {...},            the run's identity (solver, method, mesh, G, kappa_b_hat, kappa_b, ...)
//    "solver": "bim", "time": t, "vertices": N, "positions": [3N numbers, row-major],
//    "steps": accepted steps so far (= rows of timeseries.csv), "wall_seconds": w,
//    "counters": {"rejected_steps", "velocity_evaluations"},
//    "steady": SteadyStatistics::to_json(),   the recorder's keys (run_recorder.hpp; a capsule's)
//    "snapshots": [[t, "snapshot_00000.vtp"], ...],
//    "solver_state": {...}, "side_files": [...]}     (CapsuleSolver::save_state)
//
// Version 1 (no "version"; written before the run moved into the library) stored the
// dimensionless modulus under "kappa_b" and lacked the counters and running sums; it is refused
// with a message saying so.
#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "bendlab/capsule/capsule_solver.hpp"

namespace bendlab {

struct CapsuleCheckpoint {
  static constexpr int kVersion = 2;

  nlohmann::json arguments = nlohmann::json::object();
  std::string solver;
  double time = 0;
  Points positions;
  std::int64_t steps = 0;
  double wall_seconds = 0;
  SolverCounters counters;
  /// The run recorder's state (RunRecorder::state): top-level keys of the document beside the
  /// checkpoint's own, validated by the recorder on resume. Reading keeps every key that is not
  /// the checkpoint's own here.
  nlohmann::json recorder = nlohmann::json::object();
  std::vector<std::pair<double, std::string>> snapshots;
  SolverState solver_state;
  /// Set on the last checkpoint of a run that reached its end: that run's t_end ("final_for_t_end",
  /// absent otherwise). A resume to the same t_end completes the run's files from it, although
  /// `time` (the last step's) lies past t_end.
  std::optional<double> final_for_t_end;

  nlohmann::json to_json() const;
  /// Validates the whole document before returning; `source` names it in errors, which also name
  /// the key and what was expected. `num_vertices` is the mesh's vertex count.
  static CapsuleCheckpoint from_json(const nlohmann::json& j, int num_vertices, const std::string& source);

  /// Atomic write (temporary file + rename).
  void write(const std::filesystem::path& path) const;
  /// Parses and validates the text of a checkpoint (what read() does after reading the file);
  /// throws bendlab::Error, and nothing else, for any text that is not a valid checkpoint.
  static CapsuleCheckpoint parse(const std::string& text, int num_vertices, const std::string& source);
  /// Reads and validates; throws bendlab::Error for a missing, empty, unparsable or invalid file.
  static CapsuleCheckpoint read(const std::filesystem::path& path, int num_vertices);
};

}  // namespace bendlab
