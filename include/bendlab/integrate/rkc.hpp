#pragma once
// The second-order Runge-Kutta-Chebyshev method RKC2 of Sommeijer, Shampine & Verwer (1998),
// "RKC: an explicit solver for parabolic PDEs", J. Comput. Appl. Math. 88, 315-326: an explicit,
// stabilised method for dy/dt = f(t, y) whose Jacobian has its eigenvalues near the negative real
// axis, as eq. (23) of a capsule with bending stiffness (see STIFF_STEPPING.md of the
// specification: the spectrum is real and negative, the step of Cash-Karp is set by stability).
//
// One step of size h from y_n uses s >= 2 stages (F_j = f(t_n + c_j h, Y_j)):
//   Y_0 = y_n,  Y_1 = Y_0 + mu~_1 h F_0,
//   Y_j = (1 - mu_j - nu_j) Y_0 + mu_j Y_{j-1} + nu_j Y_{j-2} + mu~_j h F_{j-1} + gamma~_j h F_0,
//   y_{n+1} = Y_s,
// with the damped Chebyshev coefficients (T_j the Chebyshev polynomials of the first kind):
//   w0 = 1 + eps / s^2,  w1 = T_s'(w0) / T_s''(w0),  b_j = T_j''(w0) / T_j'(w0)^2 (j >= 2),
//   b_0 = b_1 = b_2,  a_j = 1 - b_j T_j(w0),  mu~_1 = b_1 w1,  and for j >= 2
//   mu_j = 2 b_j w0 / b_{j-1},  nu_j = -b_j / b_{j-2},  mu~_j = 2 b_j w1 / b_{j-1},
//   gamma~_j = -a_{j-1} mu~_j.
// The T_j, T_j', T_j'' at w0 follow from the three-term recurrence, so no coefficient is tabulated.
// The stability interval is [-beta(s), 0] with beta(s) ~ 0.653 s^2 for eps = 2/13, and
// s = 1 + floor(sqrt(1 + 1.54 h rho)) stages make h rho <= beta(s) (rho: the spectral radius of
// the Jacobian times the safety factor). s is capped by max_stages; a step that would need more is
// shortened to h = (s_max^2 - 1) / (1.54 rho).
//
// Local error estimate (Sommeijer et al., section 2.3), O(h^3):
//   est = 4/5 (y_n - y_{n+1}) + 2/5 h (F(y_n) + F(y_{n+1})),
//   err = norm_i( est_i / (atol + rtol max(|y_n,i|, |y_{n+1},i|)) ),
// the max norm by default (the norm of Cash-Karp, so that tolerances mean the same) or the RMS
// norm of the RKC code. A step is accepted when err <= 1.
//
// Step-size control (Sommeijer et al., section 2.4): after an accepted step
//   fac = min(grow, 0.8 (h_n / h_{n-1}) err_{n-1}^{1/3} / err_n^{2/3})   (err_n^{-1/3} on the first
//   step and after a rejection), h <- h max(shrink = 0.1, fac), and fac <= 1 on the first accepted
//   step after a rejection. After a rejection h <- h max(reject_floor, 0.8 err^{-1/3}): the floor
//   (0.5 by default) keeps one kink of f (the mixed area of a capsule switches formula when an
//   angle passes 90 degrees, so err can jump by orders of magnitude) from collapsing the step.
//
// FSAL: the error estimate needs F(y_{n+1}), which is the first stage of the next step. on_accept
// may modify y (the volume rescale of a capsule); the integrator compares y before and after the
// call and evaluates f again when any entry changed, so the next step always starts from f of the
// state it advances. Option reuse_f_after_modification keeps the stale F(y_{n+1}) instead (one
// evaluation fewer per step; the error is then that of the modification times the Jacobian, and a
// resumed run no longer repeats the uninterrupted one bit for bit).
//
// Spectral radius: a user function, or the nonlinear power iteration of the RKC code:
//   v <- y + delta (v - y)/|v - y|,  rho_k = |f(v) - f(y)| / delta,  v <- y + delta (f(v) - f(y))/|f(v) - f(y)|,
// delta = sqrt(machine eps) |y| (machine eps when y = 0), until |rho_k - rho_{k-1}| <= tol rho_k.
// The iteration is warm-started from the last vector, repeated every spectral_interval accepted
// steps and after a rejection (unless the estimate is already of the rejected step's start), and
// the estimate is multiplied by spectral_safety. It costs one evaluation per iteration.
//
// Checkpoints: checkpoint(), read inside on_accept, returns what a resumed integration needs to
// continue exactly as the uninterrupted one (the proposed step, the controller's memory, the
// spectral radius, its vector and the steps since it was estimated); restore() before integrate()
// installs it.
#include <cstdint>
#include <functional>
#include <limits>
#include <string>

#include "bendlab/integrate/integrator.hpp"

namespace bendlab {

struct RkcOptions {
  double rtol = 1e-7;
  double atol = 1e-6;
  enum class Norm { max, rms };
  Norm norm = Norm::max;  ///< of the scaled error estimate (header comment)
  double safety = 0.8;    ///< of the step-size controller
  double grow = 10.0;     ///< largest factor between consecutive steps
  double shrink = 0.1;    ///< smallest factor after an accepted step
  double reject_floor = 0.5;  ///< smallest factor after a rejected step
  double dt_initial = 1e-3;
  double dt_min = 1e-12;  ///< a step below this throws bendlab::Error
  double dt_max = std::numeric_limits<double>::infinity();
  std::int64_t max_steps = 100'000'000;  ///< accepted + rejected steps; more throws bendlab::Error
  double damping = 2.0 / 13.0;  ///< eps of w0 = 1 + eps / s^2
  int max_stages = 250;         ///< cap on s (>= 2)
  /// Fixed step mode: every step of size dt0 (dt_initial) is accepted, no error control (for
  /// convergence studies). The stage count still follows the spectral radius.
  bool adaptive = true;
  /// Keep F(y_{n+1}) as the next first stage even when on_accept modified y (header comment).
  bool reuse_f_after_modification = false;
  /// Spectral radius of df/dy at (t, y); when empty, the power iteration estimates it.
  std::function<double(double t, const Eigen::VectorXd& y)> spectral_radius;
  double spectral_safety = 1.1;    ///< factor on the estimate (not on a user function's value)
  int spectral_interval = 25;      ///< accepted steps between estimates
  int spectral_max_iterations = 50;
  double spectral_tolerance = 0.01;  ///< relative change that ends the power iteration
};

struct RkcStats : IntegratorStats {
  std::int64_t stages = 0;      ///< sum of s over all steps, accepted and rejected
  int max_stages_used = 0;
  std::int64_t stage_capped_steps = 0;    ///< steps shortened because s hit max_stages
  std::int64_t spectral_estimates = 0;    ///< power iterations (or user function calls)
  std::int64_t spectral_evaluations = 0;  ///< rhs evaluations spent on power iterations
  std::int64_t spectral_unconverged = 0;  ///< power iterations that hit the iteration limit
  std::int64_t fsal_reused = 0;           ///< steps that started from the previous F(y_{n+1})
  double spectral_radius = 0;      ///< the last value used (with the safety factor)
  double spectral_radius_max = 0;  ///< the largest value used
  double mean_stages() const { return accepted + rejected > 0 ? double(stages) / double(accepted + rejected) : 0; }
};

/// What a checkpoint stores to resume an RKC integration identically.
struct RkcCheckpoint {
  double dt_next = 0;          ///< the step the controller proposes next
  double err_previous = 0;     ///< the error norm of the last accepted step (0: none)
  double dt_previous = 0;      ///< the last accepted step
  bool after_rejection = false;
  double spectral_radius = 0;  ///< the value in use (safety factor included); 0: none yet
  Eigen::VectorXd spectral_vector;  ///< the power iteration's direction (may be empty)
  int steps_since_estimate = 0;
};

class Rkc final : public Integrator {
 public:

  explicit Rkc(RkcOptions options = {});

  /// See integrator.hpp. A fresh integration unless restore() was called since the last one;
  /// dt0 > 0 overrides the restored step. The statistics with the RKC fields: stats().
  IntegratorStats integrate(const Rhs& rhs, double t0, double t1, State& y, double dt0 = 0,
                            const OnAccept& on_accept = {}) override;
  double proposed_step() const override { return proposed_; }
  double max_step_growth() const override { return options_.grow; }
  std::string name() const override { return "rkc"; }

  /// The statistics of the current (inside on_accept) or last integration, with the RKC fields.
  const RkcStats& stats() const override { return stats_; }
  /// The state to resume from, valid inside on_accept (after that step) and after integrate().
  RkcCheckpoint checkpoint() const;
  /// Makes the next integrate() continue from `c` instead of starting fresh.
  void restore(const RkcCheckpoint& c);
  /// checkpoint() and the run totals of summary() as JSON (the spectral vector in full precision).
  nlohmann::json checkpoint_state() const override;
  void restore_checkpoint_state(const nlohmann::json& state, const std::string& source) override;
  /// Over every integration continued through checkpoints: steps, mean and max stages, the last and
  /// largest spectral radius, evaluations spent on it.
  nlohmann::json summary() const override;

  /// Number of stages for a step of size h at spectral radius rho (safety factor included):
  /// 1 + floor(sqrt(1 + 1.54 h rho)), at least 2 (uncapped).
  static int stages_for(double h, double rho);
  /// One RKC2 step of size h with s stages from (t, y) with fy = f(t, y): the new state y1.
  /// Takes s - 1 evaluations of rhs.
  void step(const Rhs& rhs, double t, const State& y, const State& fy, double h, int s, State& y1);
  /// The power iteration of the header comment at (t, y) with fy = f(t, y), warm-started from the
  /// stored vector (which it updates): the estimate without the safety factor. Counts its
  /// evaluations in `evaluations`; `converged` tells whether the tolerance was met.
  double estimate_spectral_radius(const Rhs& rhs, double t, const State& y, const State& fy,
                                  std::int64_t& evaluations, bool& converged);

  const RkcOptions& options() const { return options_; }

 private:
  double error_norm(const State& y, const State& y1, const State& est) const;
  void update_spectral_radius(const Rhs& rhs, double t, const State& y, const State& fy);

  RkcOptions options_;
  RkcStats stats_;
  double proposed_ = 0;
  // Controller memory and the spectral radius (the checkpoint).
  double err_prev_ = 0, dt_prev_ = 0;
  bool after_rejection_ = false;
  double rho_ = 0;
  State v_;
  int since_estimate_ = 0;
  bool restored_ = false;
  // Totals of the integrations before this one that it continues (summary()).
  struct Totals {
    std::int64_t steps = 0, stages = 0, spectral_evaluations = 0;
    int max_stages = 0;
    double rho_max = 0;
  };
  Totals before_, restored_totals_;
  // Work arrays.
  State f0_, f1_, yjm1_, yjm2_, yj_, fj_, y1_, est_, ysave_, pv_, pf_;
};

}  // namespace bendlab
