#pragma once
// The interface of the adaptive time integrators of dy/dt = f(t, y) (Cash-Karp 4(5) in
// cash_karp.hpp; a stiff Runge-Kutta-Chebyshev integrator will be another). A flow solver whose
// node velocity is a function of the positions (the BIM, eq. (23)) drives any of them.
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

class Integrator {
 public:
  using State = Eigen::VectorXd;
  /// dydt = f(t, y); dydt is preallocated to the size of y.
  using Rhs = std::function<void(double t, const State& y, State& dydt)>;
  /// Called after every accepted step with the new time, the step taken and the new state, which
  /// it may modify (e.g. a projection); returns false to stop the integration.
  using OnAccept = std::function<bool(double t, double dt, State& y)>;

  virtual ~Integrator() = default;
  /// "cash-karp", ...
  virtual std::string name() const = 0;
  /// Integrates y from t0 to t1 (t1 > t0), starting with step dt0 (the integrator's default when
  /// <= 0). The last step lands on t1 exactly. Throws bendlab::Error when the step size collapses.
  virtual IntegratorStats integrate(const Rhs& rhs, double t0, double t1, State& y, double dt0 = 0,
                                    const OnAccept& on_accept = {}) = 0;
  /// The step the controller will try next; inside on_accept, the proposal after that step (what a
  /// checkpoint stores to resume the integration as it would have gone on).
  virtual double proposed_step() const = 0;
  /// The counts of the integration in progress (valid inside on_accept) or of the last one.
  virtual const IntegratorStats& stats() const = 0;
};

}  // namespace bendlab
