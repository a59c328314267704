#include "bendlab/capsule/capsule_run.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>
#include <set>

#include "bendlab/capsule/bodies_snapshot.hpp"
#include "bendlab/capsule/checkpoint.hpp"
#include "bendlab/capsule/run_folder.hpp"
#include "bendlab/core/output_folder.hpp"
#include "bendlab/mesh/mesh_io.hpp"

namespace fs = std::filesystem;

namespace bendlab {

bool is_run_file(const std::string& name, const CapsuleSolver& solver) {
  const CapsuleRecorder recorder(solver.membrane());
  const RunFolder folder(".", [&](const std::string& n) { return recorder.is_output(n); },
                         [&](const std::string& n) { return solver.is_side_file(n); });
  return folder.is_run_file(name);
}

std::string compare_arguments(const nlohmann::json& here, const nlohmann::json& saved) {
  for (const auto& [key, value] : here.items()) {
    if (!saved.contains(key)) return fmt::format("{} is {} here but missing in the checkpoint", key, value.dump());
    const auto& other = saved.at(key);
    const bool same = value.is_number() && other.is_number()
                          ? std::abs(value.get<double>() - other.get<double>()) <=
                                1e-12 * std::max(std::abs(value.get<double>()), std::abs(other.get<double>()))
                          : value == other;
    if (!same) return fmt::format("{} is {} here but {} in the checkpoint", key, value.dump(), other.dump());
  }
  for (const auto& [key, value] : saved.items())
    if (!here.contains(key)) return fmt::format("{} is {} in the checkpoint but not given here", key, value.dump());
  return {};
}

namespace {

// Two times closer than this (relative, at least 1) are the same: a resume to the checkpoint's
// time completes the run instead of continuing it.
constexpr double kSameTime = 1e-12;
// A step this close to a snapshot's due time (relative to the interval) takes the snapshot.
constexpr double kScheduleTolerance = 1e-9;

void check_options(const CapsuleRunOptions& o) {
  if (o.folder.empty()) throw Error("capsule run: no output folder");
  if (!(o.t_end > 0) || !std::isfinite(o.t_end))
    throw Error(fmt::format("capsule run: t_end must be positive, got {}", o.t_end));
  if (!(o.snapshot_every > 0) || !std::isfinite(o.snapshot_every))
    throw Error(fmt::format("capsule run: snapshot_every must be positive, got {}", o.snapshot_every));
  if (o.stop_after_steps < 0) throw Error("capsule run: stop_after_steps must be >= 0");
  if (o.max_steps < 0) throw Error("capsule run: max_steps must be >= 0");
  if (!o.arguments.is_object() || !o.summary_fields.is_object())
    throw Error("capsule run: arguments and summary_fields must be JSON objects");
  if (fs::exists(o.folder) && !fs::is_directory(o.folder))
    throw Error(fmt::format("'{}' is a file, not a folder", o.folder.string()));
  const fs::path parent = parent_folder(o.folder);
  if (!fs::exists(o.folder) && !fs::is_directory(parent))
    throw Error(fmt::format("'{}': folder '{}' does not exist (a run creates its own folder only)",
                            o.folder.string(), parent.string()));
}


// One run in progress: the stages of run_solver below share its state.
class Run {
 public:
  Run(CapsuleSolver& solver, RunRecorder& recorder, const CapsuleRunOptions& o)
      : solver_(solver),
        recorder_(recorder),
        o_(o),
        folder_(o.folder, [&recorder](const std::string& n) { return recorder.is_output(n); },
                [&solver](const std::string& n) { return solver.is_side_file(n); }),
        checkpoint_path_(o.folder / "checkpoint.json"),
        start_(std::chrono::steady_clock::now()) {
    state_.arguments = o.arguments;
    state_.solver = solver.name();
  }

  // The folder is locked before anything in it is read or written. The process that writes no
  // files (a parallel run's other ranks) takes no lock: the writing one holds it for the run.
  void lock() {
    if (o_.writes_files) folder_.lock(o_.resume);
  }

  // A new run: the folder is cleared (or refused) and the initial state checkpointed.
  void start_new() {
    if (o_.writes_files) folder_.clear_for_new_run(o_.overwrite);
    recorder_.start(o_.folder, o_.t_end, o_.writes_files);
    wall_before_ = state_.wall_seconds;
    write_checkpoint(solver_.positions(), solver_.time());
  }

  // A resume: everything is checked before the folder changes. Returns whether the run is at its
  // end already (a run stopped between its final checkpoint and summary.json, killed or its
  // summary write failed, resumes to the checkpoint's own time: it takes no step and writes its
  // summary).
  bool resume() {
    const fs::path& folder = o_.folder;
    const std::string source = checkpoint_path_.string();
    if (!fs::exists(checkpoint_path_))
      throw Error(fmt::format("resume: no checkpoint in '{}' to resume from", folder.string()));
    CapsuleCheckpoint saved = CapsuleCheckpoint::read(checkpoint_path_, static_cast<int>(solver_.positions().rows()));
    for (const std::string& f : saved.solver_state.side_files)
      if (!solver_.is_side_file(f))
        throw Error(fmt::format("{}: \"side_files\" names '{}', which is not a file of the {} solver", source, f,
                                solver_.name()));
    if (o_.writes_files) folder_.check_snapshots(saved, source);
    const double largest_step = recorder_.check_resume(folder, saved, o_.t_end, o_.writes_files, source);
    if (const std::string diff = compare_arguments(o_.arguments, saved.arguments); !diff.empty())
      throw Error(fmt::format("resume: the arguments differ from the run in '{}': {}", folder.string(), diff));
    // The final checkpoint of a run lies at its last step's time, at or a little past t_end (a
    // lattice step, or a report interval, past it): it completes a run to the same t_end.
    auto same = [](double a, double b) { return std::abs(a - b) <= kSameTime * std::max(1.0, std::abs(b)); };
    const bool completing =
        same(o_.t_end, saved.time) || (saved.final_for_t_end && same(o_.t_end, *saved.final_for_t_end));
    if (!completing && !(o_.t_end > saved.time))
      throw Error(fmt::format("resume: t_end (--t-end) {} is before the checkpoint's {} = {} in '{}'; a run "
                              "continues to a later end, or to the checkpoint's own to complete its files (start a "
                              "new run in another folder instead)",
                              o_.t_end, o_.time_name, saved.time, folder.string()));
    if (saved.solver != solver_.name())
      throw Error(fmt::format("{}: \"solver\" is \"{}\", this run uses \"{}\"", source, saved.solver, solver_.name()));
    solver_.restore_state(saved.positions, saved.time, saved.counters, saved.solver_state.fields, folder, source);
    if (o_.writes_files) {
      solver_.check_resumed_steps(largest_step, source);
      // Everything is checked: from here on the folder changes.
      folder_.remove_temporaries();
    }
    recorder_.resume(folder, saved, o_.t_end, o_.writes_files, o_.on_note);
    saved.arguments = o_.arguments;
    state_ = std::move(saved);
    wall_before_ = state_.wall_seconds;
    note(completing ? fmt::format("the run in '{}' reached t_end = {:g} at its last checkpoint: writing its summary",
                                  folder.string(), o_.t_end)
                    : fmt::format("resuming at {} = {:.4g} from {}", o_.time_name, solver_.time(), source));
    return completing;
  }

  // The steps to t_end: a row per accepted step, a checkpoint per snapshot interval, progress
  // reports. Returns false when stopped before t_end (stop_after_steps, should_stop).
  bool advance() {
    const double t_start = solver_.time();
    double next_snapshot = next_snapshot_time();
    double last_progress = -std::numeric_limits<double>::infinity();
    std::int64_t steps_here = 0;
    bool stopped = false;
    double last_good_time = solver_.time();
    // A step that fails (a non-finite force or velocity, a collapsing step size) ends the run with
    // an Error that says where; the last checkpoint stays whole and resumable, and the time series
    // keeps the rows of the accepted steps (a resume truncates them to the checkpoint's).
    try {
      solver_.advance(o_.t_end, [&](const AcceptedStep& s) {
        // Before the step is counted: a step over the budget leaves no row and no checkpoint.
        if (o_.max_steps > 0 && state_.steps >= o_.max_steps)
          throw Error(fmt::format("more than {} accepted steps (the budget of --max-steps) to reach {} = {:g} "
                                  "(mean step {:.3g}; the last step {:.3g})",
                                  o_.max_steps, o_.time_name, o_.t_end,
                                  s.time / static_cast<double>(state_.steps + 1), s.dt));
        ++state_.steps;
        ++steps_here;
        last_good_time = s.time;
        recorder_.record(s);
        const bool at_end = s.time >= o_.t_end - 1e-12;
        const bool on_schedule = s.time >= next_snapshot - kScheduleTolerance * o_.snapshot_every;
        if (on_schedule || at_end) {
          write_checkpoint(*s.positions, s.time, at_end ? std::optional<double>(o_.t_end) : std::nullopt);
          if (on_schedule) next_snapshot += o_.snapshot_every;
        }
        const double now = elapsed();
        if (o_.on_progress && (now - last_progress >= o_.progress_interval_seconds || at_end)) {
          last_progress = now;
          report(s, t_start, now, at_end);
        }
        if (o_.stop_after_steps > 0 && steps_here >= o_.stop_after_steps && !at_end) {
          stopped = true;
          return false;
        }
        if (o_.should_stop && !at_end && o_.should_stop()) {
          stopped = true;
          return false;
        }
        return true;
      });
    } catch (const Error& e) {
      throw Error(fmt::format("the run failed after step {} ({} = {:.6g}): {}; the last checkpoint, at {} = "
                              "{:.6g}, is whole in '{}'",
                              state_.steps, o_.time_name, last_good_time, e.what(), o_.time_name, state_.time,
                              checkpoint_path_.string()));
    }
    return !stopped;
  }

  // summary.json (the results: no clock) and timing.json (the clock).
  CapsuleRunResult finish() {
    CapsuleRunResult result;
    result.finished = true;
    if (!o_.writes_files) return result;
    const SolverCounters counters = solver_.counters();
    nlohmann::json summary = o_.arguments;
    for (const auto& [key, value] : o_.summary_fields.items()) summary[key] = value;
    const nlohmann::json fields = {{"format_version", CapsuleCheckpoint::kVersion},
                                   {"solver", solver_.name()},
                                   {"t_end", o_.t_end},
                                   {"steps", state_.steps},
                                   {"rejected_steps", counters.rejected_steps},
                                   {"velocity_evaluations", counters.velocity_evaluations}};
    for (const auto& [key, value] : fields.items()) summary[key] = value;
    // Kept in variables: a range-for over items() of a temporary would read a destroyed object.
    const nlohmann::json recorded = recorder_.summary(o_.folder, o_.t_end, solver_.positions());
    for (const auto& [key, value] : recorded.items()) summary[key] = value;
    const nlohmann::json solver_fields = solver_.summary();
    for (const auto& [key, value] : solver_fields.items()) summary[key] = value;
    folder_.write_json("summary.json", summary);
    result.wall_seconds = wall_before_ + elapsed();
    folder_.write_json("timing.json", {{"wall_seconds", result.wall_seconds},
                                       {"wall_seconds_last_part", result.wall_seconds - wall_before_},
                                       {"resumed", o_.resume}});
    result.summary = std::move(summary);
    return result;
  }

 private:
  void note(const std::string& s) const {
    if (o_.on_note) o_.on_note(s);
  }
  double elapsed() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }

  // When the next snapshot is due: the first step at or after origin + k * snapshot_every for the
  // next k, origin the time of snapshot 0 (the run's start). An uninterrupted run adds one interval
  // per snapshot on schedule, so a resumed run counts the snapshots it has instead of adding an
  // interval to the last one's time (a step past its due time, which would shift every later
  // snapshot and checkpoint from the uninterrupted run's). A snapshot taken before its due time
  // was a final one only (at an earlier t_end) and is not counted.
  double next_snapshot_time() const {
    const auto& snaps = state_.snapshots;
    if (snaps.empty()) return state_.time + o_.snapshot_every;
    const double origin = snaps.front().first;
    auto due = [&](std::size_t k) { return origin + static_cast<double>(k) * o_.snapshot_every; };
    std::size_t on_schedule = snaps.size() - 1;  // snapshots after snapshot 0
    if (on_schedule > 0 && snaps.back().first < due(on_schedule) - kScheduleTolerance * o_.snapshot_every)
      --on_schedule;
    return due(on_schedule + 1);
  }

  // A snapshot of the bodies, then the checkpoint that lists it; the side files of the checkpoint
  // before are removed once the new one is committed. `final_for` is the t_end that this
  // checkpoint ends the run at (the last step reaches it, usually a little past it).
  void write_checkpoint(const Points& x, double t, std::optional<double> final_for = std::nullopt) {
    const std::string tag = fmt::format("{:05d}", state_.snapshots.size());
    const std::string name = fmt::format("snapshot_{}.vtp", tag);
    if (o_.writes_files) write_bodies_snapshot(o_.folder / name, solver_.bodies(), x);
    recorder_.snapshot(o_.folder, tag);  // on every process: its reads of the solver may be collective
    state_.snapshots.emplace_back(t, name);
    if (o_.writes_files) write_pvd(o_.folder / "shapes.pvd", state_.snapshots);
    const std::vector<std::string> old_side_files = state_.solver_state.side_files;
    state_.solver_state = solver_.save_state(o_.folder, tag);
    state_.time = t;
    state_.final_for_t_end = final_for;
    if (!o_.writes_files) return;
    state_.positions = x;
    state_.counters = solver_.counters();
    state_.wall_seconds = wall_before_ + elapsed();
    state_.recorder = recorder_.state();
    state_.write(checkpoint_path_);
    const std::set<std::string> keep(state_.solver_state.side_files.begin(), state_.solver_state.side_files.end());
    for (const std::string& f : old_side_files)
      if (!keep.count(f) && solver_.is_side_file(f)) {
        std::error_code ec;
        fs::remove(o_.folder / f, ec);
      }
  }

  void report(const AcceptedStep& s, double t_start, double now, bool at_end) const {
    CapsuleProgress p;
    p.time = s.time;
    p.t_start = t_start;
    p.t_end = o_.t_end;
    p.dt = s.dt;
    p.measures = recorder_.progress();
    p.D = p.theta = std::numeric_limits<double>::quiet_NaN();
    for (const auto& [name, value] : p.measures) {
      if (name == "D") p.D = value;
      if (name == "theta") p.theta = value;
    }
    p.steps = state_.steps;
    p.elapsed_seconds = now;
    const double done = (s.time - t_start) / (o_.t_end - t_start);
    p.eta_seconds = done > 0 ? now * (1 - done) / done : 0;
    p.final = at_end;
    o_.on_progress(p);
  }

  CapsuleSolver& solver_;
  RunRecorder& recorder_;
  const CapsuleRunOptions& o_;
  RunFolder folder_;
  fs::path checkpoint_path_;
  CapsuleCheckpoint state_;  // what the checkpoint carries
  std::chrono::steady_clock::time_point start_;
  double wall_before_ = 0;   // wall time of the parts before this one
};

}  // namespace

CapsuleRunResult run_solver(CapsuleSolver& solver, RunRecorder& recorder, const CapsuleRunOptions& o) {
  check_options(o);
  Run run(solver, recorder, o);
  run.lock();
  const bool completing = o.resume ? run.resume() : (run.start_new(), false);
  if (o.on_note)
    for (const std::string& line : o.start_notes) o.on_note(line);
  if (!completing && !run.advance()) return {};
  return run.finish();
}

CapsuleRunResult run_capsule(CapsuleSolver& solver, const CapsuleRunOptions& options) {
  CapsuleRecorder recorder(solver.membrane());
  return run_solver(solver, recorder, options);
}

}  // namespace bendlab
