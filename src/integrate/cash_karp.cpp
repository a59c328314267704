#include "bendlab/integrate/cash_karp.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "bendlab/core/types.hpp"

namespace bendlab {

namespace {
// The Cash-Karp tableau (Cash & Karp 1990, table 5; also Numerical Recipes, section 16.2).
constexpr double c2 = 1.0 / 5, c3 = 3.0 / 10, c4 = 3.0 / 5, c5 = 1.0, c6 = 7.0 / 8;
constexpr double a21 = 1.0 / 5;
constexpr double a31 = 3.0 / 40, a32 = 9.0 / 40;
constexpr double a41 = 3.0 / 10, a42 = -9.0 / 10, a43 = 6.0 / 5;
constexpr double a51 = -11.0 / 54, a52 = 5.0 / 2, a53 = -70.0 / 27, a54 = 35.0 / 27;
constexpr double a61 = 1631.0 / 55296, a62 = 175.0 / 512, a63 = 575.0 / 13824, a64 = 44275.0 / 110592,
                 a65 = 253.0 / 4096;
// Fifth-order weights b and fourth-order weights bs.
constexpr double b1 = 37.0 / 378, b3 = 250.0 / 621, b4 = 125.0 / 594, b6 = 512.0 / 1771;
constexpr double bs1 = 2825.0 / 27648, bs3 = 18575.0 / 48384, bs4 = 13525.0 / 55296, bs5 = 277.0 / 14336,
                 bs6 = 1.0 / 4;
}  // namespace

CashKarp::CashKarp(CashKarpOptions options) : options_(options) {
  if (!(options_.rtol >= 0) || !(options_.atol >= 0) || options_.rtol + options_.atol <= 0)
    throw Error(fmt::format("Cash-Karp: tolerances must be non-negative and not both zero (rtol {}, atol {})",
                            options_.rtol, options_.atol));
}

void CashKarp::step(const Rhs& rhs, double t, const State& y, double dt, State& y5, State& err) {
  const Eigen::Index n = y.size();
  for (auto& k : k_) k.resize(n);
  tmp_.resize(n);
  y5.resize(n);
  err.resize(n);
  rhs(t, y, k_[0]);
  tmp_ = y + dt * a21 * k_[0];
  rhs(t + c2 * dt, tmp_, k_[1]);
  tmp_ = y + dt * (a31 * k_[0] + a32 * k_[1]);
  rhs(t + c3 * dt, tmp_, k_[2]);
  tmp_ = y + dt * (a41 * k_[0] + a42 * k_[1] + a43 * k_[2]);
  rhs(t + c4 * dt, tmp_, k_[3]);
  tmp_ = y + dt * (a51 * k_[0] + a52 * k_[1] + a53 * k_[2] + a54 * k_[3]);
  rhs(t + c5 * dt, tmp_, k_[4]);
  tmp_ = y + dt * (a61 * k_[0] + a62 * k_[1] + a63 * k_[2] + a64 * k_[3] + a65 * k_[4]);
  rhs(t + c6 * dt, tmp_, k_[5]);
  y5 = y + dt * (b1 * k_[0] + b3 * k_[2] + b4 * k_[3] + b6 * k_[5]);
  err = dt * ((b1 - bs1) * k_[0] + (b3 - bs3) * k_[2] + (b4 - bs4) * k_[3] - bs5 * k_[4] + (b6 - bs6) * k_[5]);
}

double CashKarp::error_norm(const State& y, const State& y5, const State& err) const {
  double e = 0;
  for (Eigen::Index i = 0; i < y.size(); ++i) {
    const double scale = options_.atol + options_.rtol * std::max(std::abs(y[i]), std::abs(y5[i]));
    e = std::max(e, std::abs(err[i]) / scale);
  }
  return std::isfinite(e) ? e : std::numeric_limits<double>::infinity();
}

IntegratorStats CashKarp::integrate(const Rhs& rhs, double t0, double t1, State& y, double dt0,
                                    const OnAccept& on_accept) {
  if (!(t1 > t0)) throw Error(fmt::format("Cash-Karp: end time {} must be after start time {}", t1, t0));
  // The counts live in the member, so that on_accept can read them during the integration.
  IntegratorStats& st = stats_;
  st = IntegratorStats{};
  st.t = t0;
  double dt = std::min(dt0 > 0 ? dt0 : options_.dt_initial, options_.dt_max);
  proposed_ = dt;
  State y5, err;
  // The end is reached when the remaining interval is a round-off remainder of t1.
  const double eps_t = 64 * std::numeric_limits<double>::epsilon() * std::max(std::abs(t0), std::abs(t1));
  while (t1 - st.t > eps_t) {
    if (st.accepted + st.rejected >= options_.max_steps)
      throw Error(fmt::format("Cash-Karp: more than {} steps before t = {} (reached t = {})", options_.max_steps,
                              t1, st.t));
    const bool last = st.t + dt >= t1;
    const double h = last ? t1 - st.t : dt;
    step(rhs, st.t, y, h, y5, err);
    st.rhs_evaluations += 6;
    const double e = error_norm(y, y5, err);
    if (e <= 1.0) {
      st.t = last ? t1 : st.t + h;
      y.swap(y5);
      ++st.accepted;
      const double factor = e > 0 ? options_.safety * std::pow(e, -0.2) : options_.grow;
      double next = h * std::clamp(factor, options_.shrink, options_.grow);
      // A last step shortened to land on t1 says little about the step the solution allows:
      // keep the larger of the two proposals, so that a resumed integration does not restart small.
      if (last) next = std::max(next, dt);
      dt = std::min(next, options_.dt_max);
      st.dt_next = proposed_ = dt;
      if (on_accept && !on_accept(st.t, h, y)) {
        st.stopped = true;
        return st;
      }
    } else {
      ++st.rejected;
      const double factor = std::isfinite(e) ? options_.safety * std::pow(e, -0.25) : options_.shrink;
      dt = proposed_ = h * std::max(factor, options_.shrink);
      if (dt < options_.dt_min)
        throw Error(fmt::format("Cash-Karp: step size {:.3e} below the minimum {:.3e} at t = {} (error norm {:.3e}); "
                                "the system is too stiff or the state is no longer finite",
                                dt, options_.dt_min, st.t, e));
    }
  }
  st.dt_next = dt;
  return st;
}

}  // namespace bendlab
