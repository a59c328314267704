// Anderson mixing (integrate/anderson_mixing.hpp) on linear fixed-point problems, where it is
// equivalent to GMRES (Walker & Ni 2011): exact results only.
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include "bendlab/core/types.hpp"
#include "bendlab/integrate/anderson_mixing.hpp"

using namespace bendlab;

namespace {
// A non-symmetric matrix whose eigenvalues have negative real parts spread over two decades and
// imaginary parts as large: the plain iteration x += dt (A x + b) creeps, an inertial one circles.
Eigen::MatrixXd test_matrix(int n) {
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(n, n);
  for (int k = 0; k + 1 < n; k += 2) {
    const double re = -std::pow(10.0, 2.0 * k / (n - 2)), im = 0.8 * std::abs(re);
    a(k, k) = a(k + 1, k + 1) = re;
    a(k, k + 1) = im;
    a(k + 1, k) = -im;
  }
  // A change of basis that is far from orthogonal, so that A is not normal either.
  Eigen::MatrixXd p = Eigen::MatrixXd::Identity(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j) p(i, j) = 0.3 * std::sin(1.0 + i + 2.0 * j);
  return p * a * p.inverse();
}
}  // namespace

TEST(AndersonMixing, SolvesALinearProblemInAtMostNPlusOneSteps) {
  const int n = 8;
  const Eigen::MatrixXd a = test_matrix(n);
  Eigen::VectorXd b(n);
  for (int i = 0; i < n; ++i) b[i] = std::cos(0.7 * i);
  const Eigen::VectorXd exact = a.partialPivLu().solve(-b);
  const double dt = 0.5 / a.operatorNorm();
  // Depth n: the history spans the Krylov space, so the (n+1)-th step lands on the solution up to
  // round-off (GMRES's finite termination).
  AndersonMixing mixing(n);
  Eigen::VectorXd x = Eigen::VectorXd::Zero(n), dx;
  for (int k = 0; k <= n + 1; ++k) {
    mixing.step(x, dt * (a * x + b), dx);
    x += dx;
  }
  EXPECT_LT((x - exact).norm(), 1e-8 * exact.norm());
  // The plain iteration after as many steps is nowhere near: its slowest mode decays by
  // (1 - dt |Re mu_min|) per step.
  Eigen::VectorXd y = Eigen::VectorXd::Zero(n);
  for (int k = 0; k <= n + 1; ++k) y += dt * (a * y + b);
  EXPECT_GT((y - exact).norm(), 0.5 * exact.norm());
}

TEST(AndersonMixing, FirstStepIsPlainAndResetForgets) {
  AndersonMixing mixing(3);
  Eigen::VectorXd x = Eigen::VectorXd::Ones(4), f(4), dx;
  f << 1, -2, 3, -4;
  mixing.step(x, f, dx);
  EXPECT_EQ(dx, f);
  EXPECT_EQ(mixing.history(), 0);
  mixing.step(x + dx, 0.5 * f, dx);
  EXPECT_EQ(mixing.history(), 1);
  mixing.reset();
  EXPECT_EQ(mixing.history(), 0);
  mixing.step(x, f, dx);
  EXPECT_EQ(dx, f);
  EXPECT_THROW(AndersonMixing(0), Error);
  EXPECT_THROW(mixing.step(x, Eigen::VectorXd::Zero(3), dx), Error);
}
