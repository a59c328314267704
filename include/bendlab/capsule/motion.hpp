#pragma once
// The motion of a body in shear flow from its time series (docs/conventions.md §2, "Orientation
// and tank-treading"): whether it tumbles like a rigid body, swings while its membrane
// tank-treads, or does both in turn, and the periods measured.
//
// Over the motion window, the last half [t_end / 2, t_end] of the run, with the unwrapped angles
// of time_series.hpp:
//   phi(t) = axis_angle, the axis of symmetry in the shear plane (period pi: the body looks the
//            same after a half turn);
//   psi(t) = node_phase - axis_angle, the marked node's phase relative to the axis: constant for a
//            rigid body, advancing by 2 pi per turn of a tank-treading membrane.
// Periods from level crossings (linear interpolation between rows): with t_b the window's start,
// t_k the first time phi reaches phi(t_b) + k pi (k = 1..K, in the sense phi moves), the tumbling
// period (a full turn of the axis, Jeffery's T) is 2 (t_K - t_b) / K; crossings of phi(t_b) + k pi
// are exactly T / 2 apart for a periodic tumbling, whatever the phase at t_b. Likewise the
// tank-treading period (the node once round the body) from psi and levels psi(t_b) + 2 pi k.
// The swinging period is the mean spacing of the upward crossings of phi through its window mean
// (two at least), given where the axis does not tumble.
// Classification: tumbling (K_phi >= 1, psi turns less than 2 pi), swinging (phi turns less than
// pi, psi at least 2 pi: swinging with tank-treading), intermittent (both in one window), or
// undetermined (neither: a window too short, or a steady body).
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "bendlab/capsule/time_series.hpp"

namespace bendlab {

struct MotionAnalysis {
  double begin = 0, end = 0;           ///< the window
  std::string motion = "undetermined";  ///< tumbling, swinging, intermittent, undetermined
  double axis_advance = 0;             ///< phi(end) - phi(begin)
  double relative_advance = 0;         ///< psi(end) - psi(begin)
  int axis_half_turns = 0;             ///< K of phi
  int membrane_turns = 0;              ///< K of psi
  std::optional<double> tumbling_period, tank_treading_period, swinging_period;
  double axis_mean = 0, swing_amplitude = 0;  ///< mean and (max - min) / 2 of phi over the window
  /// The fields above for summary.json (periods null where not measured).
  nlohmann::json to_json() const;
};

/// The analysis of `rows` (in time order, with angles) over [t_end / 2, t_end]. Throws
/// bendlab::Error for rows without angles (the older format) or with non-finite ones.
MotionAnalysis analyse_motion(const std::vector<TimeSeriesRow>& rows, double t_end);

}  // namespace bendlab
