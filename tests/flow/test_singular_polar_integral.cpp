// The Stokeslet's integral over a triangle at the target (flow/bim/singular_polar_integral.hpp)
// against its analytic value.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "bendlab/flow/bim/singular_polar_integral.hpp"
#include "bendlab/flow/bim/triangle_quadrature.hpp"

using namespace bendlab;

namespace {

// The right isosceles triangle with legs a from the target x0 = 0 along x and y. In polar
// coordinates about x0 the hypotenuse is at rho_max = a / (cos phi + sin phi), and
//   int_0^(pi/2) dphi / (cos + sin) = sqrt(2) ln(1 + sqrt(2)) =: L,
//   int cos^2 / (cos + sin) = int sin^2 / (cos + sin) = L / 2,   int cos sin / (cos + sin) = 1 - L / 2.
// With G dS = (I + e e^T) drho dphi: for f = e_x everywhere, u = a (3L/2, 1 - L/2, 0); for f
// linear, 0 at x0 and e_x on the hypotenuse (f = (x + y) / a e_x), u = a/2 (3L/2, 1 - L/2, 0).
const double L = std::sqrt(2.0) * std::log(1.0 + std::sqrt(2.0));

Vec3 integral(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Vec3& f0, const Vec3& f1, const Vec3& f2,
              int subdivisions, int points) {
  std::vector<double> nodes, weights;
  gauss_legendre_unit(points, nodes, weights);
  return singular_polar_integral(x0, x1, x2, f0, f1, f2, subdivisions, nodes, weights);
}

}  // namespace

TEST(SingularPolarIntegral, ConstantDensityOnARightTriangle) {
  const double a = 0.7;
  const Vec3 x0 = Vec3::Zero(), x1(a, 0, 0), x2(0, a, 0), e(1, 0, 0);
  const Vec3 expect = a * Vec3(1.5 * L, 1 - 0.5 * L, 0);
  // The single layer's defaults: 2 sub-angles of 8 points.
  const Vec3 u = integral(x0, x1, x2, e, e, e, 2, 8);
  EXPECT_LT((u - expect).norm(), 1e-10 * expect.norm()) << u.transpose();
  // Converged to rounding with more points.
  EXPECT_LT((integral(x0, x1, x2, e, e, e, 4, 16) - expect).norm(), 1e-14 * expect.norm());
}

TEST(SingularPolarIntegral, LinearDensityIsIntegratedExactlyAlongTheRays) {
  const double a = 1.3;
  const Vec3 x0 = Vec3::Zero(), x1(a, 0, 0), x2(0, a, 0), e(1, 0, 0);
  const Vec3 expect = 0.5 * a * Vec3(1.5 * L, 1 - 0.5 * L, 0);
  EXPECT_LT((integral(x0, x1, x2, Vec3::Zero(), e, e, 4, 16) - expect).norm(), 1e-14 * expect.norm());
}

TEST(SingularPolarIntegral, FollowsTheTriangleInSpace) {
  // Translated and rotated with its density, the integral rotates (G is isotropic); linear in f.
  const double a = 0.4;
  const Vec3 x0 = Vec3::Zero(), x1(a, 0, 0), x2(0, a, 0);
  const Vec3 f0(0.2, -1, 0.5), f1(1, 0.3, -0.2), f2(-0.4, 0.8, 1.1);
  const Vec3 u = integral(x0, x1, x2, f0, f1, f2, 2, 8);
  const Mat3 R = Eigen::AngleAxisd(1.1, Vec3(1, -2, 0.5).normalized()).toRotationMatrix();
  const Vec3 t(3, -1, 2);
  const Vec3 ur = integral(R * x0 + t, R * x1 + t, R * x2 + t, R * f0, R * f1, R * f2, 2, 8);
  EXPECT_LT((ur - R * u).norm(), 1e-13 * u.norm());
  const Vec3 u2 = integral(x0, x1, x2, 2 * f0, 2 * f1, 2 * f2, 2, 8);
  EXPECT_LT((u2 - 2 * u).norm(), 1e-14 * u.norm());
  // The corner order of the far edge does not matter (the angle is measured from x0 -> x1).
  const Vec3 swapped = integral(x0, x2, x1, f0, f2, f1, 2, 8);
  EXPECT_LT((swapped - u).norm(), 1e-10 * u.norm());
}

TEST(SingularPolarIntegral, ObtuseCornerConverges) {
  // An obtuse corner at the target (angle 2.5 rad, where rho_max varies fastest with the angle):
  // the angular rule converges as it is refined; the defaults (2 x 8 points) are within 3e-7.
  const Vec3 x0 = Vec3::Zero(), x1(1, 0, 0), x2(std::cos(2.5), std::sin(2.5), 0), f(0.3, 0.1, -0.7);
  const Vec3 fine = integral(x0, x1, x2, f, f, f, 16, 16);
  const double coarse = (integral(x0, x1, x2, f, f, f, 1, 4) - fine).norm();
  const double medium = (integral(x0, x1, x2, f, f, f, 2, 8) - fine).norm();
  const double finer = (integral(x0, x1, x2, f, f, f, 4, 16) - fine).norm();
  EXPECT_LT(medium, 1e-3 * coarse);
  EXPECT_LT(medium, 3e-7 * fine.norm());
  EXPECT_LT(finer, 1e-12 * fine.norm());
}
