#include <gtest/gtest.h>

#include <cmath>

#include "bendlab/core/types.hpp"
#include "bendlab/integrate/cash_karp.hpp"

using namespace bendlab;
using State = CashKarp::State;

namespace {
const CashKarp::Rhs decay = [](double, const State& y, State& d) { d = -y; };
// y0'' = -y0 as a first-order system; energy y0^2 + y1^2 is conserved, y0 = cos t.
const CashKarp::Rhs oscillator = [](double, const State& y, State& d) {
  d[0] = y[1];
  d[1] = -y[0];
};
}  // namespace

TEST(CashKarp, ExponentialDecayToTolerance) {
  for (double tol : {1e-6, 1e-9}) {
    CashKarpOptions o;
    o.rtol = tol;
    o.atol = tol;
    CashKarp ck(o);
    State y(1);
    y << 1.0;
    const auto st = ck.integrate(decay, 0.0, 5.0, y);
    EXPECT_DOUBLE_EQ(st.t, 5.0);
    // Local errors are below tol per step and decay along the way: the global error stays ~tol.
    EXPECT_LT(std::abs(y[0] - std::exp(-5.0)), 10 * tol) << tol;
    EXPECT_EQ(st.rhs_evaluations, 6 * (st.accepted + st.rejected));
  }
}

TEST(CashKarp, HarmonicOscillatorToTolerance) {
  double prev_err = 0, prev_steps = 0;
  for (double tol : {1e-5, 1e-10}) {
    CashKarpOptions o;
    o.rtol = tol;
    o.atol = tol;
    CashKarp ck(o);
    State y(2);
    y << 1.0, 0.0;
    const double T = 4 * M_PI;  // two periods
    const auto st = ck.integrate(oscillator, 0.0, T, y);
    const double err = std::hypot(y[0] - 1.0, y[1]);
    // Errors accumulate over the N steps: bound by N * tol.
    EXPECT_LT(err, st.accepted * tol) << tol;
    if (prev_steps > 0) {
      // Per-step error ~ C dt^5 (the fourth-order member controls the step), so the number of
      // steps grows like tol^(-1/5): a factor 10 for tol / 1e5; and the error falls with tol.
      const double ratio = st.accepted / prev_steps;
      EXPECT_GT(ratio, 6.0);
      EXPECT_LT(ratio, 16.0);
      EXPECT_LT(err, 1e-3 * prev_err);
    }
    prev_err = err;
    prev_steps = static_cast<double>(st.accepted);
  }
}

TEST(CashKarp, FixedStepOrders) {
  // One step of y' = -y from y = 1: the fifth-order solution has local error O(dt^6), the embedded
  // difference y5 - y4 is O(dt^5). Halving dt divides them by 64 and 32.
  CashKarp ck;
  State y(1), y5, err;
  y << 1.0;
  double e5[2], ed[2];
  const double dts[2] = {0.1, 0.05};
  for (int k = 0; k < 2; ++k) {
    ck.step(decay, 0.0, y, dts[k], y5, err);
    e5[k] = std::abs(y5[0] - std::exp(-dts[k]));
    ed[k] = std::abs(err[0]);
  }
  EXPECT_NEAR(std::log2(e5[0] / e5[1]), 6.0, 0.3);
  EXPECT_NEAR(std::log2(ed[0] / ed[1]), 5.0, 0.3);
}

TEST(CashKarp, CallbackCanModifyStateAndStop) {
  CashKarp ck;
  State y(1);
  y << 1.0;
  int calls = 0;
  const auto st = ck.integrate(decay, 0.0, 10.0, y, 0.0, [&](double t, double, State& s) {
    s[0] = 1.0;  // reset: the solution stays at 1 on every accepted step
    ++calls;
    return t < 1.0;
  });
  EXPECT_TRUE(st.stopped);
  EXPECT_EQ(calls, st.accepted);
  EXPECT_GE(st.t, 1.0);
  EXPECT_LT(st.t, 10.0);
  EXPECT_EQ(y[0], 1.0);
}

TEST(CashKarp, CollapsingStepThrows) {
  // y' = 1/(1 - t) blows up at t = 1: the step collapses before the end time 2.
  CashKarpOptions o;
  o.dt_min = 1e-10;
  CashKarp ck(o);
  State y(1);
  y << 0.0;
  const CashKarp::Rhs blow = [](double t, const State&, State& d) { d[0] = 1.0 / (1.0 - t); };
  EXPECT_THROW(ck.integrate(blow, 0.0, 2.0, y), Error);
  CashKarpOptions few;
  few.max_steps = 3;
  CashKarp ck2(few);
  y << 1.0;
  EXPECT_THROW(ck2.integrate(decay, 0.0, 100.0, y, 1e-3), Error);
}
