#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "bendlab/flow/lbm/parameters.hpp"

using namespace bendlab;
using namespace bendlab::lbm;

namespace {
// The message of the Error thrown for `in`, or "" if none.
std::string error_of(const CapsuleRunInput& in) {
  try {
    capsule_run_parameters(in);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}
}  // namespace

TEST(CapsuleRunParameters, PaperSetup) {
  const CapsuleRunInput in;  // R = 13.5, tau = 1, 9.5 R x 9.5 R x 19 R, Re = 0.26
  const CapsuleRunParameters p = capsule_run_parameters(in);
  EXPECT_EQ(p.nx, 128);
  EXPECT_EQ(p.ny, 128);
  EXPECT_EQ(p.nz, std::lround(19 * 13.5));
  EXPECT_DOUBLE_EQ(p.nu, 1.0 / 6.0);
  EXPECT_DOUBLE_EQ(p.wall_velocity * in.radius / p.nu, in.reynolds);
  EXPECT_DOUBLE_EQ(p.shear_rate, 2 * p.wall_velocity / p.nz);
  EXPECT_DOUBLE_EQ(p.mu * p.shear_rate * in.radius / p.kS, in.G);
  EXPECT_DOUBLE_EQ(p.kB / (in.radius * in.radius * p.kS), in.kB_hat);
  EXPECT_DOUBLE_EQ(p.kV, 100 * p.kS / in.radius);  // 100 kS in units of R
  EXPECT_LT(p.mach, 0.01);
  EXPECT_GE(p.steps * p.shear_rate, 10.0);
  EXPECT_LT((p.steps - 1) * p.shear_rate, 10.0);
  EXPECT_TRUE(p.warnings.empty());
  const LatticeConfig c = p.lattice_config();
  EXPECT_EQ(c.nz, p.nz);
  EXPECT_TRUE(c.walls);
  EXPECT_DOUBLE_EQ(c.wall_velocity, p.wall_velocity);
}

TEST(CapsuleRunParameters, RejectsBadSetups) {
  CapsuleRunInput in;
  in.tau = 0.5;
  EXPECT_NE(error_of(in).find("tau"), std::string::npos);
  in = {};
  in.box_x = 2.0;  // 27 nodes < 2 (R + 1)
  EXPECT_NE(error_of(in).find("does not contain the capsule"), std::string::npos);
  in = {};
  in.box_y = 1.5;
  EXPECT_NE(error_of(in).find("box y"), std::string::npos);
  in = {};
  in.box_z = 2.1;  // nz = 28: the walls at +-14 touch R + 1 = 14.5
  EXPECT_NE(error_of(in).find("touches the walls"), std::string::npos);
  in = {};
  in.reynolds = 5.0;  // v = 5/6/13.5, Ma = 0.107
  EXPECT_NE(error_of(in).find("Mach"), std::string::npos);
  in = {};
  in.G = 0;
  EXPECT_NE(error_of(in).find("G ="), std::string::npos);
  in = {};
  EXPECT_EQ(error_of(in), "");
}

TEST(CapsuleRunParameters, TheBoxMustHoldTheShapesExtentNotTheSpheres) {
  // A prolate spheroid c/a = 4 of the unit sphere's volume, its axis along x (tilt 90): half-axes
  // 4^(2/3) = 2.52 along x and 4^(-1/3) = 0.63 across. At R = 3 it is 15 nodes long: a period of
  // 9 nodes (box 3 R) would overlap it with its own image.
  CapsuleRunInput in;
  in.radius = 3;
  in.box_x = 3;
  in.box_y = 3;
  in.box_z = 4;
  EXPECT_EQ(error_of(in), "");  // the sphere of radius R fits
  in.half_extent = {std::cbrt(16.0), std::cbrt(0.25), std::cbrt(0.25)};
  EXPECT_NE(error_of(in).find("box x of 9 nodes does not contain the capsule"), std::string::npos) << error_of(in);
  in.box_x = 6;  // 18 nodes > 2 (3 * 2.52 + 1)
  EXPECT_EQ(error_of(in), "");
  // Upright (tilt 0) the same body reaches for the walls.
  in.half_extent = {std::cbrt(0.25), std::cbrt(0.25), std::cbrt(16.0)};
  in.box_z = 5;  // the walls at +-7.5 against 3 * 2.52 + 1
  EXPECT_NE(error_of(in).find("touches the walls"), std::string::npos) << error_of(in);
}

TEST(CapsuleRunParameters, WarnsAboveThePapersReynoldsNumber) {
  CapsuleRunInput in;
  in.reynolds = 0.5;
  const CapsuleRunParameters p = capsule_run_parameters(in);
  ASSERT_FALSE(p.warnings.empty());
  EXPECT_NE(p.warnings.front().find("Reynolds"), std::string::npos);
}

TEST(CapsuleRunParameters, AHugeRadiusIsRefusedWithoutOverflow) {
  CapsuleRunInput in;
  in.radius = 1e9;  // 9.5e9 nodes along x: beyond an int
  const std::string e = error_of(in);
  EXPECT_NE(e.find("box x"), std::string::npos) << e;
  EXPECT_NE(e.find("lower the radius"), std::string::npos) << e;
  EXPECT_EQ(e.find("-"), std::string::npos) << e;  // no negative node count
}

TEST(CapsuleRunParameters, WarnsWhenTauNearAHalfMakesTheRunLong) {
  CapsuleRunInput in;
  in.tau = 0.500001;
  in.gamma_t_end = 0.01;
  const CapsuleRunParameters p = capsule_run_parameters(in);
  ASSERT_FALSE(p.warnings.empty());
  EXPECT_NE(p.warnings.front().find(std::to_string(p.steps) + " lattice steps"), std::string::npos)
      << p.warnings.front();
}
