#include "bendlab/capsule/capsule_run.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>
#include <regex>
#include <set>

#include "bendlab/capsule/capsule_shape.hpp"
#include "bendlab/capsule/checkpoint.hpp"
#include "bendlab/capsule/motion.hpp"
#include "bendlab/core/atomic_file.hpp"
#include "bendlab/core/folder_lock.hpp"
#include "bendlab/geometry/measures.hpp"
#include "bendlab/mesh/mesh_io.hpp"

namespace fs = std::filesystem;

namespace bendlab {

TimeSeriesRow capsule_sample(const MembraneModel& membrane, const Points& x, double t, double dt,
                             const MotionMarkers* markers) {
  TimeSeriesRow r;
  r.t = t;
  r.dt = dt;
  const CapsuleShape shape = capsule_shape(membrane.topology(), x);
  r.D = shape.D;
  r.theta = shape.theta;
  const MotionAngles angles = motion_angles(
      shape, x, markers ? *markers : motion_markers(membrane.topology(), membrane.initial_positions()));
  r.axis_angle = angles.axis;
  r.node_phase = angles.node;
  r.volume = shape.volume;
  r.area = surface_area(membrane.topology(), x);
  const std::optional<double> eb = membrane.bending_energy(x);
  r.E_bend = eb ? *eb : std::numeric_limits<double>::quiet_NaN();
  r.E_elastic = membrane.elastic_energy(x);
  return r;
}

namespace {

// The run's own files, apart from the solver's side files. D_theta.png is the command line's plot
// of the run; it belongs to the run as much as the files it is drawn from.
bool is_run_output(const std::string& name, const CapsuleSolver& solver) {
  static const std::set<std::string> fixed = {"timeseries.csv", "checkpoint.json", "summary.json",
                                              "timing.json",    "shapes.pvd",      "D_theta.png"};
  static const std::regex snapshot_re(R"(snapshot_\d{5,}\.vtp)");
  return fixed.count(name) > 0 || std::regex_match(name, snapshot_re) || solver.is_side_file(name);
}

}  // namespace

bool is_run_file(const std::string& name, const CapsuleSolver& solver) {
  if (is_run_output(name, solver)) return true;
  // A temporary the run itself can have left, and nothing that merely looks like one: AtomicFile's
  // "<output>.tmp" and mkstemp's six letters or digits, or the parallel fluid checkpoint's
  // "<side file>.tmp" (parallel/distributed_checkpoint.hpp). "timeseries.csv.tmp-backup" or
  // "summary.json.tmp" are a user's files, which --resume and --overwrite must not remove.
  if (const std::optional<std::string> target = atomic_temp_target(name)) return is_run_output(*target, solver);
  static const std::string bare = ".tmp";
  return name.size() > bare.size() && name.compare(name.size() - bare.size(), bare.size(), bare) == 0 &&
         solver.is_side_file(name.substr(0, name.size() - bare.size()));
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
  const fs::path parent = o.folder.has_parent_path() ? o.folder.parent_path() : fs::path(".");
  if (!fs::exists(o.folder) && !fs::is_directory(parent))
    throw Error(fmt::format("'{}': folder '{}' does not exist (a run creates its own folder only)",
                            o.folder.string(), parent.string()));
}

// The names of the run's files in folder (temporaries included; folders are no run's), sorted.
std::vector<std::string> run_files_in(const fs::path& folder, const CapsuleSolver& solver, bool temporaries_only) {
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(folder)) {
    const std::string name = entry.path().filename().string();
    if (entry.is_directory() && !entry.is_symlink()) continue;
    if (!is_run_file(name, solver)) continue;
    if (temporaries_only && is_run_output(name, solver)) continue;
    names.push_back(name);
  }
  std::sort(names.begin(), names.end());
  return names;
}

void remove_files(const fs::path& folder, const std::vector<std::string>& names) {
  for (const std::string& name : names) {
    std::error_code ec;
    fs::remove(folder / name, ec);
    if (ec) throw Error(fmt::format("cannot remove '{}': {}", (folder / name).string(), ec.message()));
  }
}

// The checkpoint's snapshot list: snapshot_00000.vtp, snapshot_00001.vtp, ... (every one this run
// wrote, in order), the last at the checkpoint's time. A resume writes snapshot_<N>.vtp next (N
// entries in the list), which a run killed between a snapshot and its checkpoint may have left;
// a snapshot beyond it in the folder belongs to a later history than the checkpoint's and would be
// overwritten. (The listed files need not be present: a study's run folder moves between machines
// without them.)
void check_snapshots(const CapsuleCheckpoint& c, const fs::path& folder, const std::string& source) {
  if (c.snapshots.empty())
    throw Error(fmt::format("{}: \"snapshots\" is empty; a checkpoint is written with a snapshot, so it lists one at "
                            "least",
                            source));
  for (std::size_t k = 0; k < c.snapshots.size(); ++k) {
    const std::string expected = fmt::format("snapshot_{:05d}.vtp", k);
    if (c.snapshots[k].second != expected)
      throw Error(fmt::format("{}: \"snapshots\" entry {} names '{}', expected '{}'", source, k, c.snapshots[k].second,
                              expected));
  }
  static const std::regex snapshot_re(R"(snapshot_(\d{5,})\.vtp)");
  for (const auto& entry : fs::directory_iterator(folder)) {
    const std::string name = entry.path().filename().string();
    std::smatch m;
    if (std::regex_match(name, m, snapshot_re) && m[1].str().size() < 10 &&
        std::stoll(m[1].str()) > static_cast<long long>(c.snapshots.size()))
      throw Error(fmt::format("{}: \"snapshots\" lists {} snapshots but '{}' holds '{}', a later one; the resumed run "
                              "would overwrite it",
                              source, c.snapshots.size(), folder.string(), name));
  }
  const double last = c.snapshots.back().first;
  if (std::abs(last - c.time) > 1e-12 * std::max(1.0, std::abs(c.time)))
    throw Error(fmt::format("{}: the last of \"snapshots\" is at gamma t = {}, the checkpoint's \"time\" is {}",
                            source, last, c.time));
}

// The kept rows of timeseries.csv against each other and the checkpoint: finite, positive steps
// that add up to the times (to the digits the file keeps), the last at the checkpoint's time.
// Returns the largest step.
double check_kept_rows(const std::vector<TimeSeriesRow>& rows, double time, const fs::path& series,
                       const std::string& checkpoint) {
  double largest = 0;
  for (std::size_t k = 0; k < rows.size(); ++k) {
    const TimeSeriesRow& r = rows[k];
    const std::int64_t line = static_cast<std::int64_t>(k) + 2;
    if (!std::isfinite(r.t) || !std::isfinite(r.dt) || !(r.dt > 0))
      throw Error(fmt::format("'{}' line {}: gamma_t {} and dt {} must be finite, dt positive", series.string(), line,
                              r.t, r.dt));
    if (k > 0) {
      const double advanced = r.t - rows[k - 1].t;
      if (std::abs(advanced - r.dt) > 1e-5 * r.dt + 1e-9 * std::abs(r.t))
        throw Error(fmt::format("'{}' line {}: gamma_t advanced by {:.6g} since the row before, but dt is {:.6g}",
                                series.string(), line, advanced, r.dt));
    }
    largest = std::max(largest, r.dt);
  }
  if (!rows.empty() && std::abs(rows.back().t - time) > 1e-9 * std::max(1.0, std::abs(time)))
    throw Error(fmt::format("{}: \"time\" is {} and \"steps\" {}, but row {} of '{}' is at gamma t = {}", checkpoint,
                            time, rows.size(), rows.size(), series.string(), rows.back().t));
  return largest;
}

nlohmann::json finite_or_null(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

}  // namespace

CapsuleRunResult run_capsule(CapsuleSolver& solver, const CapsuleRunOptions& o) {
  check_options(o);
  const MembraneModel& membrane = solver.membrane();
  const fs::path folder = o.folder;
  const fs::path checkpoint_path = folder / "checkpoint.json";
  const fs::path series_path = folder / "timeseries.csv";
  auto note = [&](const std::string& s) {
    if (o.on_note) o.on_note(s);
  };

  // State carried by the checkpoint.
  CapsuleCheckpoint state;
  state.arguments = o.arguments;
  state.solver = solver.name();
  state.steady = SteadyStatistics(SteadyWindow::for_run(o.t_end));

  // The folder is locked before anything in it is read or written. The process that writes no
  // files (a parallel run's other ranks) takes no lock: the writing one holds it for the run.
  std::optional<FolderLock> lock;
  if (o.writes_files) {
    if (!o.resume && !fs::exists(folder)) {
      std::error_code ec;
      fs::create_directory(folder, ec);
      if (ec && !fs::is_directory(folder))
        throw Error(fmt::format("cannot create the run folder '{}': {}", folder.string(), ec.message()));
    }
    if (fs::is_directory(folder)) lock.emplace(folder, "run folder");
  }

  std::optional<TimeSeriesFile> series;
  // The angles of the time series are unwrapped against the row before (the first row against the
  // initial shape); a resumed run continues from the last kept row.
  const MotionMarkers markers = motion_markers(membrane.topology(), membrane.initial_positions());
  MotionAngles unwrapped = motion_angles(capsule_shape(membrane.topology(), membrane.initial_positions()),
                                         membrane.initial_positions(), markers);
  // Resumed at its end already (t_end is the checkpoint's time): only the summary is missing.
  bool completing = false;
  if (o.resume) {
    if (!fs::exists(checkpoint_path))
      throw Error(fmt::format("resume: no checkpoint in '{}' to resume from", folder.string()));
    CapsuleCheckpoint saved = CapsuleCheckpoint::read(checkpoint_path, membrane.num_vertices());
    for (const std::string& f : saved.solver_state.side_files)
      if (!solver.is_side_file(f))
        throw Error(fmt::format("{}: \"side_files\" names '{}', which is not a file of the {} solver",
                                checkpoint_path.string(), f, solver.name()));
    std::vector<TimeSeriesRow> kept;
    if (o.writes_files) {
      check_snapshots(saved, folder, checkpoint_path.string());
      kept = read_time_series_head(series_path, saved.steps);
    }
    const double largest_step = check_kept_rows(kept, saved.time, series_path, checkpoint_path.string());
    if (!kept.empty() && std::isfinite(kept.back().axis_angle) && std::isfinite(kept.back().node_phase))
      unwrapped = {kept.back().axis_angle, kept.back().node_phase};
    if (const std::string diff = compare_arguments(o.arguments, saved.arguments); !diff.empty())
      throw Error(fmt::format("resume: the arguments differ from the run in '{}': {}", folder.string(), diff));
    // A run stopped between its final checkpoint and summary.json (killed, or its summary write
    // failed) resumes to the checkpoint's own time: it takes no step and writes its summary.
    completing = std::abs(o.t_end - saved.time) <= kSameTime * std::max(1.0, std::abs(saved.time));
    if (!completing && !(o.t_end > saved.time))
      throw Error(fmt::format("resume: t_end (--t-end) {} is before the checkpoint's gamma t = {} in '{}'; a run "
                              "continues to a later end, or to the checkpoint's own to complete its files (start a "
                              "new run in another folder instead)",
                              o.t_end, saved.time, folder.string()));
    if (saved.solver != solver.name())
      throw Error(fmt::format("{}: \"solver\" is \"{}\", this run uses \"{}\"", checkpoint_path.string(), saved.solver,
                              solver.name()));
    solver.restore_state(saved.positions, saved.time, saved.counters, saved.solver_state.fields, folder,
                         checkpoint_path.string());
    if (o.writes_files) {
      solver.check_resumed_steps(largest_step, checkpoint_path.string());
      // Everything is checked: from here on the folder changes.
      remove_files(folder, run_files_in(folder, solver, true));
      series.emplace(TimeSeriesFile::resume(series_path, saved.steps));
    }
    const SteadyWindow window = SteadyWindow::for_run(o.t_end);
    if (o.writes_files && !(saved.steady.window() == window)) {
      note(fmt::format("t_end moved the steady window from [{}, {}] to [{}, {}]: its sums are recomputed from {}",
                       saved.steady.window().begin, saved.steady.window().end, window.begin, window.end,
                       series_path.string()));
      const std::vector<TimeSeriesRow> rows = read_time_series(series_path);
      saved.steady = SteadyStatistics(window);
      for (const TimeSeriesRow& r : rows) saved.steady.add(r);
    }
    saved.arguments = o.arguments;
    state = std::move(saved);
    note(completing ? fmt::format("the run in '{}' reached t_end = {:g} at its last checkpoint: writing its summary",
                                  folder.string(), o.t_end)
                    : fmt::format("resuming at gamma t = {:.4g} from {}", solver.time(), checkpoint_path.string()));
  }

  const auto start = std::chrono::steady_clock::now();
  auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); };
  const double wall_before = state.wall_seconds;

  auto write_checkpoint = [&](const Points& x, double t) {
    const std::string tag = fmt::format("{:05d}", state.snapshots.size());
    const std::string name = fmt::format("snapshot_{}.vtp", tag);
    if (o.writes_files) write_mesh(folder / name, membrane.topology(), x);
    state.snapshots.emplace_back(t, name);
    if (o.writes_files) write_pvd(folder / "shapes.pvd", state.snapshots);
    const std::vector<std::string> old_side_files = state.solver_state.side_files;
    state.solver_state = solver.save_state(folder, tag);
    if (!o.writes_files) {
      state.time = t;
      return;
    }
    state.time = t;
    state.positions = x;
    state.counters = solver.counters();
    state.wall_seconds = wall_before + elapsed();
    state.write(checkpoint_path);
    const std::set<std::string> keep(state.solver_state.side_files.begin(), state.solver_state.side_files.end());
    for (const std::string& f : old_side_files)
      if (!keep.count(f) && solver.is_side_file(f)) {
        std::error_code ec;
        fs::remove(folder / f, ec);
      }
  };

  if (!o.resume) {
    if (o.writes_files) {
      const std::vector<std::string> old = run_files_in(folder, solver, false);
      if (!old.empty() && !o.overwrite)
        throw Error(fmt::format("'{}' holds another run ('{}'{}); continue it with --resume, or replace it with "
                                "--overwrite",
                                folder.string(), old.front(), old.size() > 1 ? fmt::format(" and {} more", old.size() - 1)
                                                                             : std::string()));
      remove_files(folder, old);
      series.emplace(TimeSeriesFile::create(series_path));
    }
    write_checkpoint(solver.positions(), solver.time());
  }

  const double t_start = solver.time();
  double next_snapshot =
      (state.snapshots.empty() ? state.time : state.snapshots.back().first) + o.snapshot_every;
  double last_progress = -std::numeric_limits<double>::infinity();
  std::int64_t steps_here = 0;
  bool stopped = false;
  double last_good_time = solver.time();
  // A step that fails (a non-finite force or velocity, a collapsing step size) ends the run with
  // an Error that says where; the last checkpoint stays whole and resumable, and timeseries.csv
  // keeps the rows of the accepted steps (a resume truncates them to the checkpoint's).
  try {
    if (!completing) solver.advance(o.t_end, [&](const AcceptedStep& s) {
      // Before the step is counted: a step over the budget leaves no row and no checkpoint.
      if (o.max_steps > 0 && state.steps >= o.max_steps)
        throw Error(fmt::format("more than {} accepted steps (the budget of --max-steps) to reach gamma t = {:g} "
                                "(mean gamma dt {:.3g}; the last step {:.3g})",
                                o.max_steps, o.t_end, s.time / static_cast<double>(state.steps + 1), s.dt));
      ++state.steps;
      ++steps_here;
      last_good_time = s.time;
      TimeSeriesRow row = capsule_sample(membrane, *s.positions, s.time, s.dt, &markers);
      // raw + k period with k from the row before: the result depends on the row before through
      // the integer k only, so a resumed run (which reads the row before back from the file)
      // writes the very same values.
      row.axis_angle = unwrap_angle(unwrapped.axis, row.axis_angle, M_PI);
      row.node_phase = unwrap_angle(unwrapped.node, row.node_phase, 2 * M_PI);
      unwrapped = {row.axis_angle, row.node_phase};
      if (series) series->append(row);
      state.steady.add(row);
      const bool at_end = s.time >= o.t_end - 1e-12;
      if (s.time >= next_snapshot - 1e-9 * o.snapshot_every || at_end) {
        write_checkpoint(*s.positions, s.time);
        next_snapshot += o.snapshot_every;
      }
      const double now = elapsed();
      if (o.on_progress && (now - last_progress >= o.progress_interval_seconds || at_end)) {
        last_progress = now;
        CapsuleProgress p;
        p.time = s.time;
        p.t_start = t_start;
        p.t_end = o.t_end;
        p.dt = s.dt;
        p.D = row.D;
        p.theta = row.theta;
        p.steps = state.steps;
        p.elapsed_seconds = now;
        const double done = (s.time - t_start) / (o.t_end - t_start);
        p.eta_seconds = done > 0 ? now * (1 - done) / done : 0;
        p.final = at_end;
        o.on_progress(p);
      }
      if (o.stop_after_steps > 0 && steps_here >= o.stop_after_steps && !at_end) {
        stopped = true;
        return false;
      }
      if (o.should_stop && !at_end && o.should_stop()) {
        stopped = true;
        return false;
      }
      return true;
    });
  } catch (const Error& e) {
    throw Error(fmt::format("the run failed after step {} (gamma t = {:.6g}): {}; the last checkpoint, at gamma t = "
                            "{:.6g}, is whole in '{}'",
                            state.steps, last_good_time, e.what(), state.time, checkpoint_path.string()));
  }
  CapsuleRunResult result;
  if (stopped) return result;
  if (!o.writes_files) {
    result.finished = true;
    return result;
  }

  const SolverCounters counters = solver.counters();
  nlohmann::json summary = o.arguments;
  for (const auto& [key, value] : o.summary_fields.items()) summary[key] = value;
  const SteadyStatistics& st = state.steady;
  const nlohmann::json fields = {
      {"format_version", CapsuleCheckpoint::kVersion},
      {"solver", solver.name()},
      {"vertices", membrane.num_vertices()},
      {"triangles", membrane.topology().num_faces()},
      {"t_end", o.t_end},
      {"steady_window", {st.window().begin, st.window().end}},
      {"D_steady", finite_or_null(st.D())},
      {"theta_steady", finite_or_null(st.theta())},
      {"mean_gamma_dt", finite_or_null(st.mean_dt())},
      {"steady_rows", st.count()},
      {"steps", state.steps},
      {"rejected_steps", counters.rejected_steps},
      {"velocity_evaluations", counters.velocity_evaluations},
      {"final_volume", capsule_shape(membrane.topology(), solver.positions()).volume},
      {"initial_volume", membrane.initial_volume()}};
  for (const auto& [key, value] : fields.items()) summary[key] = value;
  // The motion, from the time series as written (a resumed run reads the same file); a run resumed
  // in a file of the older format has no angles, and no motion.
  if (series && !series->legacy()) {
    nlohmann::json motion = analyse_motion(read_time_series(series_path), o.t_end).to_json();
    motion["marked_node"] = markers.node;
    motion["axis"] = markers.short_axis ? "short" : "long";
    summary["motion"] = motion;
  }
  const nlohmann::json solver_fields = solver.summary();
  for (const auto& [key, value] : solver_fields.items()) summary[key] = value;
  AtomicFile f(folder / "summary.json");
  f.stream() << summary.dump(2) << '\n';
  f.commit();
  // The clock lives apart from the results, so that summary.json depends on the run alone.
  result.wall_seconds = wall_before + elapsed();
  const nlohmann::json timing = {{"wall_seconds", result.wall_seconds},
                                 {"wall_seconds_last_part", result.wall_seconds - wall_before},
                                 {"resumed", o.resume}};
  AtomicFile t(folder / "timing.json");
  t.stream() << timing.dump(2) << '\n';
  t.commit();
  result.finished = true;
  result.summary = std::move(summary);
  return result;
}

}  // namespace bendlab
