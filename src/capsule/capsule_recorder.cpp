#include "bendlab/capsule/capsule_recorder.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "bendlab/capsule/checkpoint.hpp"
#include "bendlab/capsule/motion.hpp"
#include "bendlab/geometry/measures.hpp"

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

constexpr const char* kSeries = "timeseries.csv";

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

CapsuleRecorder::CapsuleRecorder(const MembraneModel& membrane)
    : membrane_(membrane),
      markers_(motion_markers(membrane.topology(), membrane.initial_positions())),
      unwrapped_(motion_angles(capsule_shape(membrane.topology(), membrane.initial_positions()),
                               membrane.initial_positions(), markers_)) {}

bool CapsuleRecorder::is_output(const std::string& name) const { return name == kSeries; }

void CapsuleRecorder::start(const fs::path& folder, double t_end, bool writes_files) {
  steady_ = SteadyStatistics(SteadyWindow::for_run(t_end));
  if (writes_files) series_.emplace(TimeSeriesFile::create(folder / kSeries));
}

double CapsuleRecorder::check_resume(const fs::path& folder, const CapsuleCheckpoint& saved, double t_end,
                                     bool writes_files, const std::string& source) {
  (void)t_end;
  const fs::path series_path = folder / kSeries;
  std::vector<TimeSeriesRow> kept;
  if (writes_files) kept = read_time_series_head(series_path, saved.steps);
  const double largest_step = check_kept_rows(kept, saved.time, series_path, source);
  if (!kept.empty() && std::isfinite(kept.back().axis_angle) && std::isfinite(kept.back().node_phase))
    unwrapped_ = {kept.back().axis_angle, kept.back().node_phase};
  if (!saved.recorder.contains("steady")) throw Error(fmt::format("{}: \"steady\" is missing", source));
  if (!saved.recorder.at("steady").is_object())
    throw Error(fmt::format("{}: \"steady\" must be an object, got {}", source, saved.recorder.at("steady").type_name()));
  SteadyStatistics steady = SteadyStatistics::from_json(saved.recorder.at("steady"), source + ": \"steady\"");
  if (steady.count() > saved.steps)
    throw Error(fmt::format("{}: \"steady\" counts {} rows in the window but the run has {} steps", source,
                            steady.count(), saved.steps));
  saved_steady_ = steady;
  return largest_step;
}

void CapsuleRecorder::resume(const fs::path& folder, const CapsuleCheckpoint& saved, double t_end, bool writes_files,
                             const std::function<void(const std::string&)>& note) {
  if (!saved_steady_) throw Error("capsule recorder: resume without check_resume");
  const fs::path series_path = folder / kSeries;
  steady_ = *saved_steady_;
  saved_steady_.reset();
  if (writes_files) series_.emplace(TimeSeriesFile::resume(series_path, saved.steps));
  const SteadyWindow window = SteadyWindow::for_run(t_end);
  if (writes_files && !(steady_.window() == window)) {
    if (note)
      note(fmt::format("t_end moved the steady window from [{}, {}] to [{}, {}]: its sums are recomputed from {}",
                       steady_.window().begin, steady_.window().end, window.begin, window.end, series_path.string()));
    const std::vector<TimeSeriesRow> rows = read_time_series(series_path);
    steady_ = SteadyStatistics(window);
    for (const TimeSeriesRow& r : rows) steady_.add(r);
  }
}

void CapsuleRecorder::record(const AcceptedStep& s) {
  TimeSeriesRow row = capsule_sample(membrane_, *s.positions, s.time, s.dt, &markers_);
  row.axis_angle = unwrap_angle(unwrapped_.axis, row.axis_angle, M_PI);
  row.node_phase = unwrap_angle(unwrapped_.node, row.node_phase, 2 * M_PI);
  unwrapped_ = {row.axis_angle, row.node_phase};
  if (series_) series_->append(row);
  steady_.add(row);
  last_ = row;
}

ProgressMeasures CapsuleRecorder::progress() const { return {{"D", last_.D}, {"theta", last_.theta}}; }

nlohmann::json CapsuleRecorder::state() const { return {{"steady", steady_.to_json()}}; }

nlohmann::json CapsuleRecorder::summary(const fs::path& folder, double t_end, const Points& positions) const {
  const SteadyStatistics& st = steady_;
  nlohmann::json fields = {{"vertices", membrane_.num_vertices()},
                           {"triangles", membrane_.topology().num_faces()},
                           {"steady_window", {st.window().begin, st.window().end}},
                           {"D_steady", finite_or_null(st.D())},
                           {"theta_steady", finite_or_null(st.theta())},
                           {"mean_gamma_dt", finite_or_null(st.mean_dt())},
                           {"steady_rows", st.count()},
                           {"final_volume", capsule_shape(membrane_.topology(), positions).volume},
                           {"initial_volume", membrane_.initial_volume()}};
  // The motion, from the time series as written (a resumed run reads the same file); a run resumed
  // in a file of the older format has no angles, and no motion.
  if (series_ && !series_->legacy()) {
    nlohmann::json motion = analyse_motion(read_time_series(folder / kSeries), t_end).to_json();
    motion["marked_node"] = markers_.node;
    motion["axis"] = markers_.short_axis ? "short" : "long";
    fields["motion"] = motion;
  }
  return fields;
}

}  // namespace bendlab
