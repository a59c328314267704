#pragma once
// The common interface of the adaptive time integrators of dy/dt = f(t, y) (eq. (23) for a capsule):
// Cash-Karp 4(5) (cash_karp.hpp) and the stabilised second-order Runge-Kutta-Chebyshev method
// (rkc.hpp). A driver holds an AdaptiveIntegrator and does not depend on the method.
//
// Contract shared by every implementation:
//   - integrate() advances y from t0 to t1 > t0, starting with step dt0 (the method's default
//     first step when dt0 <= 0); the last step is shortened to land on t1 exactly.
//   - After every accepted step on_accept(t, dt, y) is called with the new time, the step taken and
//     the new state; it may modify y (e.g. a projection or the volume rescale of a capsule) and
//     returns false to stop. The integrator continues from the state as on_accept left it.
//   - proposed_step(), read inside on_accept, is the step the controller will try next: what a
//     checkpoint stores to resume the integration as it would have gone on.
//   - Bad input, a step below dt_min or more than max_steps steps throw bendlab::Error.
#include <cstdint>
#include <functional>
#include <string>

#include <Eigen/Dense>

namespace bendlab {

struct IntegratorStats {
  std::int64_t accepted = 0, rejected = 0, rhs_evaluations = 0;
  double t = 0;          ///< time reached
  double dt_next = 0;    ///< the step the controller proposes next (to resume an integration)
  bool stopped = false;  ///< the callback asked to stop
};

class AdaptiveIntegrator {
 public:
  using State = Eigen::VectorXd;
  /// dydt = f(t, y); dydt is preallocated to the size of y.
  using Rhs = std::function<void(double t, const State& y, State& dydt)>;
  /// Called after every accepted step with the new time, the step taken and the new state, which
  /// it may modify (e.g. a projection); returns false to stop the integration.
  using OnAccept = std::function<bool(double t, double dt, State& y)>;

  virtual ~AdaptiveIntegrator() = default;

  /// Integrates y from t0 to t1 (t1 > t0), starting with step dt0 (the default first step when
  /// dt0 <= 0). The last step is shortened to land on t1 exactly.
  virtual IntegratorStats integrate(const Rhs& rhs, double t0, double t1, State& y, double dt0 = 0,
                                    const OnAccept& on_accept = {}) = 0;
  /// The step the controller will try next (see the contract above).
  virtual double proposed_step() const = 0;
  /// Short name of the method ("cash-karp", "rkc2").
  virtual std::string name() const = 0;
};

}  // namespace bendlab
