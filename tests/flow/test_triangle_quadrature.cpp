// The quadrature rules of the boundary integral (flow/bim/triangle_quadrature.hpp): each exact to
// its degree and not beyond.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "bendlab/core/types.hpp"
#include "bendlab/flow/bim/triangle_quadrature.hpp"

using namespace bendlab;

namespace {
double factorial(int n) {
  double f = 1;
  for (int k = 2; k <= n; ++k) f *= k;
  return f;
}
// The 7-point rule's value of l0^a l1^b l2^c over a triangle of area 1 and the exact one,
// 2 a! b! c! / (a + b + c + 2)!.
double rule7(int a, int b, int c) {
  const TriangleRule7& r = triangle_rule7();
  double s = 0;
  for (int q = 0; q < TriangleRule7::size; ++q)
    s += r.weight[q] * std::pow(r.bary[q][0], a) * std::pow(r.bary[q][1], b) * std::pow(r.bary[q][2], c);
  return s;
}
double exact(int a, int b, int c) { return 2 * factorial(a) * factorial(b) * factorial(c) / factorial(a + b + c + 2); }
}  // namespace

TEST(TriangleQuadrature, Rule7AndGaussLegendreOnTheirDegrees) {
  // Degree-5 rule: integrates l0^a l1^b l2^c exactly for a + b + c <= 5, = 2 a! b! c! / (a+b+c+2)!
  // over a triangle of area 1 (times 1/area ... here the weights sum to one, so area = 1).
  const TriangleRule7& r = triangle_rule7();
  auto fact = [](int n) { double f = 1; for (int k = 2; k <= n; ++k) f *= k; return f; };
  for (int a = 0; a <= 5; ++a)
    for (int b = 0; a + b <= 5; ++b)
      for (int c = 0; a + b + c <= 5; ++c) {
        double s = 0;
        for (int q = 0; q < 7; ++q)
          s += r.weight[q] * std::pow(r.bary[q][0], a) * std::pow(r.bary[q][1], b) * std::pow(r.bary[q][2], c);
        EXPECT_NEAR(s, 2 * fact(a) * fact(b) * fact(c) / fact(a + b + c + 2), 1e-15);
      }
  std::vector<double> x, w;
  gauss_legendre_unit(8, x, w);
  for (int p = 0; p <= 15; ++p) {  // exact to degree 2n - 1
    double s = 0;
    for (int q = 0; q < 8; ++q) s += w[q] * std::pow(x[q], p);
    EXPECT_NEAR(s, 1.0 / (p + 1), 1e-15) << p;
  }
}

TEST(TriangleQuadrature, Rule7IsExactToDegreeFiveAndNotSix) {
  // The points are barycentric (they sum to 1) and inside the triangle, the weights sum to 1.
  const TriangleRule7& r = triangle_rule7();
  double total = 0;
  for (int q = 0; q < TriangleRule7::size; ++q) {
    EXPECT_NEAR(r.bary[q][0] + r.bary[q][1] + r.bary[q][2], 1.0, 1e-15);
    for (int k = 0; k < 3; ++k) EXPECT_GT(r.bary[q][k], 0.0);
    total += r.weight[q];
  }
  EXPECT_NEAR(total, 1.0, 1e-15);
  // Degree 6: some monomial is missed, by more than rounding.
  double worst = 0;
  for (int a = 0; a <= 6; ++a)
    for (int b = 0; a + b <= 6; ++b) worst = std::max(worst, std::abs(rule7(a, b, 6 - a - b) - exact(a, b, 6 - a - b)));
  EXPECT_GT(worst, 1e-6);
}

TEST(TriangleQuadrature, GaussLegendreIsExactToDegree2nMinus1AndNot2n) {
  for (const int n : {1, 2, 3, 5, 8, 12}) {
    std::vector<double> x, w;
    gauss_legendre_unit(n, x, w);
    ASSERT_EQ(static_cast<int>(x.size()), n);
    ASSERT_EQ(static_cast<int>(w.size()), n);
    for (int p = 0; p < 2 * n; ++p) {
      double s = 0;
      for (int q = 0; q < n; ++q) s += w[q] * std::pow(x[q], p);
      EXPECT_NEAR(s, 1.0 / (p + 1), 1e-14) << n << " points, degree " << p;
    }
    // Degree 2n: P_n(2x - 1)^2 integrates to 1 / (2n + 1) but vanishes at every node.
    double s = 0;
    for (int q = 0; q < n; ++q) {
      const double t = 2 * x[q] - 1;
      double p0 = 1, p1 = t;
      for (int k = 2; k <= n; ++k) {
        const double p2 = ((2 * k - 1) * t * p1 - (k - 1) * p0) / k;
        p0 = p1;
        p1 = p2;
      }
      s += w[q] * p1 * p1;
    }
    EXPECT_LT(s, 1e-12) << n << " points";
    EXPECT_GT(1.0 / (2 * n + 1) - s, 0.5 / (2 * n + 1)) << n << " points";
    for (int q = 0; q < n; ++q) {
      EXPECT_GT(x[q], 0.0);
      EXPECT_LT(x[q], 1.0);
      EXPECT_GT(w[q], 0.0);
    }
  }
  std::vector<double> x, w;
  EXPECT_THROW(gauss_legendre_unit(0, x, w), Error);
}
