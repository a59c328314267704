#include "bendlab/surfaces/taylor_jet.hpp"

#include <gtest/gtest.h>

#include <cmath>

using bendlab::Jet;

TEST(TaylorJet, SinCosCoefficients) {
  const double t = 0.7;
  Jet<4> s, c;
  Jet<4>::sin_cos(std::sin(t), std::cos(t), s, c);
  EXPECT_DOUBLE_EQ(s.derivative(0), std::sin(t));
  EXPECT_DOUBLE_EQ(s.derivative(1), std::cos(t));
  EXPECT_DOUBLE_EQ(s.derivative(2), -std::sin(t));
  EXPECT_DOUBLE_EQ(s.derivative(3), -std::cos(t));
  EXPECT_DOUBLE_EQ(s.derivative(4), std::sin(t));
  // sin^2 + cos^2 = 1 identically: every higher coefficient vanishes.
  const Jet<4> one = s * s + c * c;
  EXPECT_NEAR(one.c[0], 1.0, 1e-15);
  for (int k = 1; k <= 4; ++k) EXPECT_NEAR(one.c[k], 0.0, 1e-15);
}

TEST(TaylorJet, DivisionAndSqrtInvertProducts) {
  Jet<4> a, b;
  a.c = {1.5, -0.3, 0.7, 0.2, -1.1};
  b.c = {2.0, 0.4, -0.5, 0.9, 0.3};
  const Jet<4> q = (a * b) / b;
  const Jet<4> r = sqrt(a * a);
  for (int k = 0; k <= 4; ++k) {
    EXPECT_NEAR(q.c[k], a.c[k], 1e-14);
    EXPECT_NEAR(r.c[k], a.c[k], 1e-14);
  }
}

TEST(TaylorJet, DerivativeOfPolynomial) {
  // p(t) = t^4 at t0 = 2: p' = 4 t^3 = 32, p'' = 12 t^2 = 48, p''' = 24 t = 48, p'''' = 24.
  Jet<4> t;
  t.c = {2.0, 1.0, 0.0, 0.0, 0.0};
  const Jet<4> p = t * t * t * t;
  EXPECT_DOUBLE_EQ(p.derivative(0), 16.0);
  EXPECT_DOUBLE_EQ(p.derivative(1), 32.0);
  EXPECT_DOUBLE_EQ(p.derivative(2), 48.0);
  EXPECT_DOUBLE_EQ(p.derivative(3), 48.0);
  EXPECT_DOUBLE_EQ(p.derivative(4), 24.0);
  const Jet<3> dp = derivative(p);
  EXPECT_DOUBLE_EQ(dp.derivative(0), 32.0);
  EXPECT_DOUBLE_EQ(dp.derivative(3), 24.0);
}
