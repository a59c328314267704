#pragma once
// The recorder of one capsule (run_recorder.hpp): timeseries.csv (time_series.hpp), one row per
// accepted step, the steady statistics (steady_statistics.hpp) and, at the end, the motion
// (motion.hpp) read back from the file as written.
//
// The angles of the time series are unwrapped against the row before (the first row against the
// initial shape); a resumed run continues from the last kept row: raw + k period with k from the
// row before, so the result depends on the row before through the integer k only and a resumed
// run writes the very same values. A file of the older 8-column format keeps that format.
//
// Checkpoint state: {"steady": SteadyStatistics::to_json()}. If t_end moved the steady window, a
// resume recomputes the sums from timeseries.csv (to the precision of the file: dt has 6 digits,
// so about 1e-6 relative) and says so.
#include <optional>

#include "bendlab/capsule/capsule_shape.hpp"
#include "bendlab/capsule/run_recorder.hpp"
#include "bendlab/capsule/steady_statistics.hpp"
#include "bendlab/capsule/time_series.hpp"
#include "bendlab/membrane/membrane_model.hpp"

namespace bendlab {

/// The time-series row of positions x at time t after a step dt: D and theta of the equivalent
/// ellipsoid (capsule_shape.hpp), volume, area, the membrane's energies, and the axis angle and
/// node phase of `markers` (default: motion_markers of the membrane's initial positions), folded
/// into their ranges (the run unwraps them).
TimeSeriesRow capsule_sample(const MembraneModel& membrane, const Points& x, double t, double dt,
                             const MotionMarkers* markers = nullptr);

class CapsuleRecorder final : public RunRecorder {
 public:
  /// Records the capsule `membrane` (kept by reference: it must outlive the recorder).
  explicit CapsuleRecorder(const MembraneModel& membrane);

  bool is_output(const std::string& name) const override;
  void start(const std::filesystem::path& folder, double t_end, bool writes_files) override;
  double check_resume(const std::filesystem::path& folder, const CapsuleCheckpoint& saved, double t_end,
                      bool writes_files, const std::string& source) override;
  void resume(const std::filesystem::path& folder, const CapsuleCheckpoint& saved, double t_end, bool writes_files,
              const std::function<void(const std::string&)>& note) override;
  void record(const AcceptedStep& step) override;
  /// D and theta of the last row.
  ProgressMeasures progress() const override;
  nlohmann::json state() const override;
  /// vertices, triangles, steady_window, D_steady, theta_steady, mean_gamma_dt, steady_rows,
  /// final_volume, initial_volume, and motion (not for a file of the older format).
  nlohmann::json summary(const std::filesystem::path& folder, double t_end, const Points& positions) const override;

  const TimeSeriesRow& last_row() const { return last_; }

 private:
  const MembraneModel& membrane_;
  MotionMarkers markers_;
  MotionAngles unwrapped_;
  SteadyStatistics steady_;
  std::optional<TimeSeriesFile> series_;
  TimeSeriesRow last_;
  // Between check_resume and resume: the steady sums of the checkpoint.
  std::optional<SteadyStatistics> saved_steady_;
};

}  // namespace bendlab
