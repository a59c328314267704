#pragma once
// The interface of the adaptive time integrators of dy/dt = f(t, y): Cash-Karp 4(5) (cash_karp.hpp)
// and the stabilised second-order Runge-Kutta-Chebyshev method (rkc.hpp) for the stiffness bending
// gives eq. (23). A flow solver whose node velocity is a function of the positions (the BIM) drives
// any of them.
//
// Contract shared by every implementation:
//   - integrate() advances y from t0 to t1 > t0, starting with step dt0 (the method's default
//     first step when dt0 <= 0); the last step is shortened to land on t1 exactly.
//   - After every accepted step on_accept(t, dt, y) is called with the new time, the step taken and
//     the new state; it may modify y (e.g. a projection or the volume rescale of a capsule) and
//     returns false to stop. The integrator continues from the state as on_accept left it.
//   - proposed_step() and checkpoint_state(), read inside on_accept, are what a checkpoint stores to
//     resume the integration as it would have gone on: restore_checkpoint_state() before the next
//     integrate() (with dt0 = the stored proposed step) continues it instead of starting afresh.
//   - Bad input, a step below dt_min or more than max_steps steps throw bendlab::Error.
#include <cstdint>
#include <functional>
#include <string>

#include <Eigen/Dense>
#include <nlohmann/json.hpp>

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
  /// The largest factor between a step and the step proposed after it (a resumed run checks a
  /// checkpoint's proposed step against the steps taken).
  virtual double max_step_growth() const = 0;
  /// The counts of the integration in progress (valid inside on_accept) or of the last one.
  virtual const IntegratorStats& stats() const = 0;
  /// The state beyond proposed_step() that an identical resume needs (controller memory and the
  /// like), as a JSON object; empty for a method that needs none (Cash-Karp).
  virtual nlohmann::json checkpoint_state() const { return nlohmann::json::object(); }
  /// Makes the next integrate() continue from a checkpoint_state(); throws bendlab::Error naming
  /// `source` and the key when the state is not one this method wrote.
  virtual void restore_checkpoint_state(const nlohmann::json& state, const std::string& source) {
    (void)state;
    (void)source;
  }
  /// Statistics of the method for a run's summary, counted over every integration continued from
  /// a checkpoint_state() (JSON object; empty when the method has nothing beyond stats()).
  virtual nlohmann::json summary() const { return nlohmann::json::object(); }
};

}  // namespace bendlab
