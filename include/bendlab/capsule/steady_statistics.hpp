#pragma once
// The steady state of a capsule run (table 4 and figure 12b of the paper), defined ONCE here:
//   window: gamma t in [5, 10], or the last half [t_end / 2, t_end] of a run ending before 10;
//   D_steady, theta_steady: time averages over the window of the rows whose time lies in it, each
//     row weighted by the step that led to it (its values hold over that step);
//   mean_gamma_dt: the plain mean of those rows' steps.
// The running sums are plain doubles added in row order; a checkpoint stores them at full
// precision, so a resumed run ends with the very same numbers as an uninterrupted one.
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>

#include "bendlab/capsule/time_series.hpp"

namespace bendlab {

struct SteadyWindow {
  double begin = 0, end = 0;
  /// [5, 10] for t_end >= 10, else [t_end / 2, t_end].
  static SteadyWindow for_run(double t_end);
  /// begin <= t <= end (+ 1e-12 for the round-off of the last step).
  bool contains(double t) const;
  bool operator==(const SteadyWindow&) const = default;
};

class SteadyStatistics {
 public:
  explicit SteadyStatistics(SteadyWindow window = {}) : window_(window) {}

  /// Adds a row if its time lies in the window.
  void add(const TimeSeriesRow& row);

  const SteadyWindow& window() const { return window_; }
  std::int64_t count() const { return count_; }
  /// NaN while the window holds no row.
  double D() const;
  double theta() const;
  double mean_dt() const;

  /// {"window": [begin, end], "weight", "D_dt", "theta_dt", "dt_sum", "count"}: the running sums.
  nlohmann::json to_json() const;
  /// Inverse of to_json; throws bendlab::Error naming `where` and the key for a wrong type or value.
  static SteadyStatistics from_json(const nlohmann::json& j, const std::string& where);

 private:
  SteadyWindow window_;
  double weight_ = 0, D_dt_ = 0, theta_dt_ = 0, dt_sum_ = 0;
  std::int64_t count_ = 0;
};

}  // namespace bendlab
