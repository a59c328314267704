#include "bendlab/capsule/motion.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace bendlab {

namespace {

struct Sample {
  double t, phi, psi;
};

/// The first times the series v (in time order from s[0]) reaches v0 + k * step * sign, k = 1, 2, ...
/// (sign: that of the net advance); linear interpolation between samples.
std::vector<double> level_times(const std::vector<Sample>& s, double Sample::*v, double step) {
  std::vector<double> times;
  const double v0 = s.front().*v;
  const double sign = s.back().*v >= v0 ? 1 : -1;
  int k = 1;
  for (std::size_t i = 1; i < s.size(); ++i) {
    while (sign * (s[i].*v - v0) >= k * step) {
      const double level = v0 + sign * k * step;
      const double a = s[i - 1].*v, b = s[i].*v;
      const double f = b != a ? std::clamp((level - a) / (b - a), 0.0, 1.0) : 1.0;
      times.push_back(s[i - 1].t + f * (s[i].t - s[i - 1].t));
      ++k;
    }
  }
  return times;
}

nlohmann::json optional_json(const std::optional<double>& v) {
  return v ? nlohmann::json(*v) : nlohmann::json(nullptr);
}

}  // namespace

nlohmann::json MotionAnalysis::to_json() const {
  return {{"window", {begin, end}},
          {"motion", motion},
          {"axis_advance", axis_advance},
          {"relative_advance", relative_advance},
          {"axis_half_turns", axis_half_turns},
          {"membrane_turns", membrane_turns},
          {"tumbling_period", optional_json(tumbling_period)},
          {"tank_treading_period", optional_json(tank_treading_period)},
          {"swinging_period", optional_json(swinging_period)},
          {"axis_mean", axis_mean},
          {"swing_amplitude", swing_amplitude}};
}

MotionAnalysis analyse_motion(const std::vector<TimeSeriesRow>& rows, double t_end) {
  MotionAnalysis m;
  m.begin = t_end / 2;
  m.end = t_end;
  std::vector<Sample> s;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const TimeSeriesRow& r = rows[i];
    if (!std::isfinite(r.axis_angle) || !std::isfinite(r.node_phase))
      throw Error(fmt::format("motion analysis: row {} (gamma t = {}) has no finite axis_angle and node_phase", i + 1,
                              r.t));
    if (r.t < m.begin) continue;
    const Sample here{r.t, r.axis_angle, r.node_phase - r.axis_angle};
    if (s.empty() && i > 0 && r.t > m.begin) {
      // The window's start, interpolated between the rows around it.
      const TimeSeriesRow& p = rows[i - 1];
      const double f = (m.begin - p.t) / (r.t - p.t);
      const Sample before{p.t, p.axis_angle, p.node_phase - p.axis_angle};
      s.push_back({m.begin, before.phi + f * (here.phi - before.phi), before.psi + f * (here.psi - before.psi)});
    }
    s.push_back(here);
  }
  if (s.size() < 2) return m;
  m.begin = s.front().t;
  m.axis_advance = s.back().phi - s.front().phi;
  m.relative_advance = s.back().psi - s.front().psi;
  const std::vector<double> half_turns = level_times(s, &Sample::phi, M_PI);
  const std::vector<double> turns = level_times(s, &Sample::psi, 2 * M_PI);
  m.axis_half_turns = static_cast<int>(half_turns.size());
  m.membrane_turns = static_cast<int>(turns.size());
  if (!half_turns.empty()) m.tumbling_period = 2 * (half_turns.back() - m.begin) / half_turns.size();
  if (!turns.empty()) m.tank_treading_period = (turns.back() - m.begin) / turns.size();
  // Mean (time-weighted, trapezoids) and extent of phi.
  double integral = 0, lo = s.front().phi, hi = lo;
  for (std::size_t i = 1; i < s.size(); ++i) {
    integral += 0.5 * (s[i].phi + s[i - 1].phi) * (s[i].t - s[i - 1].t);
    lo = std::min(lo, s[i].phi);
    hi = std::max(hi, s[i].phi);
  }
  const double span = s.back().t - s.front().t;
  m.axis_mean = span > 0 ? integral / span : s.front().phi;
  m.swing_amplitude = 0.5 * (hi - lo);
  if (half_turns.empty()) {
    std::vector<double> up;
    for (std::size_t i = 1; i < s.size(); ++i)
      if (s[i - 1].phi < m.axis_mean && s[i].phi >= m.axis_mean) {
        const double f = (m.axis_mean - s[i - 1].phi) / (s[i].phi - s[i - 1].phi);
        up.push_back(s[i - 1].t + f * (s[i].t - s[i - 1].t));
      }
    if (up.size() >= 2) m.swinging_period = (up.back() - up.front()) / (up.size() - 1);
  }
  const bool tumbles = !half_turns.empty(), treads = !turns.empty();
  m.motion = tumbles && treads ? "intermittent" : tumbles ? "tumbling" : treads ? "swinging" : "undetermined";
  return m;
}

}  // namespace bendlab
