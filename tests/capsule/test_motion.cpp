#include <gtest/gtest.h>

#include <cmath>

#include "bendlab/capsule/capsule_shape.hpp"
#include "bendlab/capsule/motion.hpp"

using namespace bendlab;

namespace {
/// Rows every dt up to t_end with axis angle phi(t) and node phase phi(t) + psi(t).
template <class Phi, class Psi>
std::vector<TimeSeriesRow> rows(double t_end, double dt, Phi phi, Psi psi) {
  std::vector<TimeSeriesRow> r;
  for (int k = 1; k * dt <= t_end + 1e-12; ++k) {
    TimeSeriesRow row;
    row.t = k * dt;
    row.dt = dt;
    row.axis_angle = phi(row.t);
    row.node_phase = phi(row.t) + psi(row.t);
    r.push_back(row);
  }
  return r;
}

/// Jeffery's orbit of a spheroid of aspect ratio r in the shear plane, unwrapped:
/// tan phi = r tan(omega t), omega = r / (1 + r^2) (gamma = 1), the angle from e_z towards e_x.
double jeffery(double t, double r) {
  const double w = r / (1 + r * r) * t;
  return std::atan(r * std::tan(w)) + M_PI * std::floor(w / M_PI + 0.5);
}
}  // namespace

TEST(Motion, AnglesAreMeasuredInTheSenseTheFlowTurns) {
  // u = gamma z e_x turns e_z towards e_x.
  EXPECT_NEAR(axis_angle(Vec3(0, 0, 1)), 0.0, 1e-15);
  EXPECT_NEAR(axis_angle(Vec3(1, 0, 1)), M_PI / 4, 1e-15);
  EXPECT_NEAR(axis_angle(Vec3(-1, 0, -1)), M_PI / 4, 1e-15);  // a director
  EXPECT_NEAR(axis_angle(Vec3(1, 0, 0)), M_PI / 2, 1e-15);
  EXPECT_NEAR(shear_plane_phase(Vec3(0, 0, -1)), M_PI, 1e-15);
  EXPECT_NEAR(unwrap_angle(3.0, -3.0, 2 * M_PI), -3.0 + 2 * M_PI, 1e-15);
  EXPECT_NEAR(unwrap_angle(10 * M_PI + 1.4, -1.5, M_PI), 11 * M_PI - 1.5, 1e-12);
}

TEST(Motion, JefferyTumblingGivesJefferysPeriod) {
  const double r = 0.5, T = 2 * M_PI * (r + 1 / r);
  const auto series = rows(40, 1e-3, [&](double t) { return jeffery(t, r) + 0.3; }, [](double) { return 1.0; });
  const MotionAnalysis m = analyse_motion(series, 40);
  EXPECT_EQ(m.motion, "tumbling");
  ASSERT_TRUE(m.tumbling_period.has_value());
  // Level crossings are exactly T/2 apart; linear interpolation between rows 1e-3 apart.
  EXPECT_NEAR(*m.tumbling_period, T, 1e-5 * T);
  EXPECT_FALSE(m.tank_treading_period.has_value());
  EXPECT_FALSE(m.swinging_period.has_value());
  EXPECT_EQ(m.axis_half_turns, 2);
  EXPECT_EQ(m.membrane_turns, 0);
  EXPECT_NEAR(m.relative_advance, 0.0, 1e-12);
}

TEST(Motion, SwingingWithTankTreading) {
  const double Ts = 3.0, Ttt = 6.0;
  const auto series = rows(
      30, 1e-3, [&](double t) { return 1.2 + 0.1 * std::sin(2 * M_PI * t / Ts); },
      [&](double t) { return 2 * M_PI * t / Ttt + 0.2 * std::sin(4 * M_PI * t / Ttt); });
  const MotionAnalysis m = analyse_motion(series, 30);
  EXPECT_EQ(m.motion, "swinging");
  ASSERT_TRUE(m.tank_treading_period.has_value());
  EXPECT_NEAR(*m.tank_treading_period, Ttt, 1e-5);
  ASSERT_TRUE(m.swinging_period.has_value());
  EXPECT_NEAR(*m.swinging_period, Ts, 1e-4);
  EXPECT_NEAR(m.swing_amplitude, 0.1, 1e-6);
  EXPECT_NEAR(m.axis_mean, 1.2, 1e-4);
  EXPECT_FALSE(m.tumbling_period.has_value());
  EXPECT_EQ(m.to_json().at("window").at(0).get<double>(), 15.0);
}

TEST(Motion, IntermittentAndUndetermined) {
  // The axis turns over and the membrane goes round relative to it in one window.
  auto m = analyse_motion(rows(20, 1e-3, [](double t) { return 0.4 * t; }, [](double t) { return 0.8 * t; }), 20);
  EXPECT_EQ(m.motion, "intermittent");
  EXPECT_NEAR(*m.tumbling_period, 2 * M_PI / 0.4, 1e-4);
  EXPECT_NEAR(*m.tank_treading_period, 2 * M_PI / 0.8, 1e-4);
  // A steady body (or a window too short for either) is undetermined.
  m = analyse_motion(rows(2, 1e-3, [](double) { return 0.4; }, [](double) { return 0.0; }), 2);
  EXPECT_EQ(m.motion, "undetermined");
  EXPECT_FALSE(m.tumbling_period || m.tank_treading_period || m.swinging_period);
  // The membrane turning against the flow's sense counts as well (the sign is the advance's).
  m = analyse_motion(rows(20, 1e-3, [](double) { return 0.4; }, [](double t) { return -t; }), 20);
  EXPECT_EQ(m.motion, "swinging");
  EXPECT_NEAR(m.relative_advance, -10.0, 1e-9);
}

TEST(Motion, RowsWithoutAnglesAreRefused) {
  auto series = rows(1, 0.1, [](double) { return 0.0; }, [](double) { return 0.0; });
  series[3].axis_angle = std::nan("");
  EXPECT_THROW(analyse_motion(series, 1), Error);
}

TEST(TimeSeries, TheOlderFormatIsReadWithoutAngles) {
  const auto rows = parse_time_series(std::string(legacy_time_series_header()) + "\n0.1,0.2,0.3,4,5,nan,6,0.1\n", "old");
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_TRUE(std::isnan(rows[0].axis_angle));
  EXPECT_TRUE(std::isnan(rows[0].node_phase));
  // A row of the older format in a file of the new one (and the reverse) is malformed.
  EXPECT_THROW(parse_time_series(std::string(time_series_header()) + "\n0.1,0.2,0.3,4,5,nan,6,0.1\n", "new"), Error);
  EXPECT_THROW(parse_time_series(std::string(legacy_time_series_header()) + "\n0.1,0.2,0.3,4,5,nan,6,0.1,1,2\n", "old"),
               Error);
  TimeSeriesRow r;
  r.t = 0.5;
  r.axis_angle = 7.25;
  r.node_phase = -1.5;
  const auto back = parse_time_series(std::string(time_series_header()) + "\n" + format_time_series_row(r), "new");
  EXPECT_EQ(back[0].axis_angle, 7.25);
  EXPECT_EQ(back[0].node_phase, -1.5);
  EXPECT_EQ(format_time_series_row(r, true).find("7.25"), std::string::npos);
}
