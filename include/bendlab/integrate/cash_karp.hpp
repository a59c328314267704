#pragma once
// Adaptive explicit Runge-Kutta of Cash and Karp [119]: an embedded 4(5) pair, advancing with the
// fifth-order solution (local extrapolation), as used for eq. (23) in paper section 4.3.1.
//
// Error control: err = max_i |y5_i - y4_i| / (atol + rtol * max(|y_i|, |y5_i|)), a step is
// accepted when err <= 1. The next step is dt * clamp(safety * err^(-1/5), shrink, grow) after an
// accepted step and dt * max(shrink, safety * err^(-1/4)) after a rejected one.
#include <cstdint>
#include <limits>

#include "bendlab/integrate/integrator.hpp"

namespace bendlab {

struct CashKarpOptions {
  double rtol = 1e-7;
  double atol = 1e-6;
  double safety = 0.9;
  double grow = 5.0;    ///< largest factor between consecutive steps
  double shrink = 0.2;  ///< smallest factor between consecutive steps
  double dt_initial = 1e-3;
  double dt_min = 1e-12;  ///< a step below this throws bendlab::Error
  double dt_max = std::numeric_limits<double>::infinity();
  std::int64_t max_steps = 100'000'000;  ///< accepted + rejected steps; more throws bendlab::Error
};

using CashKarpStats = IntegratorStats;

class CashKarp final : public Integrator {
 public:
  explicit CashKarp(CashKarpOptions options = {});

  std::string name() const override { return "cash-karp"; }

  /// Integrates y from t0 to t1 (t1 > t0), starting with step dt0 (options.dt_initial when <= 0).
  /// The last step is shortened to land on t1 exactly.
  IntegratorStats integrate(const Rhs& rhs, double t0, double t1, State& y, double dt0 = 0,
                            const OnAccept& on_accept = {}) override;

  /// One Cash-Karp step of size dt from (t, y): the fifth-order result y5 and the difference
  /// y5 - y4 of the embedded pair. Takes 6 evaluations of rhs.
  void step(const Rhs& rhs, double t, const State& y, double dt, State& y5, State& err);

  /// The error norm of the header comment for the step y -> y5 with difference err.
  double error_norm(const State& y, const State& y5, const State& err) const;

  const CashKarpOptions& options() const { return options_; }
  /// The step the controller will try next; inside on_accept, the proposal after that step
  /// (what a checkpoint should store to resume the integration as it would have gone on).
  double proposed_step() const override { return proposed_; }
  double max_step_growth() const override { return options_.grow; }
  const IntegratorStats& stats() const override { return stats_; }

 private:
  CashKarpOptions options_;
  double proposed_ = 0;
  IntegratorStats stats_;
  State k_[6], tmp_;
};

}  // namespace bendlab
