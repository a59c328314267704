#pragma once
// Anderson acceleration of a fixed-point iteration (Anderson 1965, J. ACM 12:547; the form of Walker
// & Ni 2011, SIAM J. Numer. Anal. 49:1715, "type II" with mixing 1). The plain iteration is
// x_{k+1} = x_k + f_k, f_k = f(x_k) its update (for the overdamped relaxation of bendlab stretch,
// f = dt R(x)). Anderson keeps the last `depth` differences dx_j = x_j - x_{j-1} and
// df_j = f_j - f_{j-1} and steps to
//   x_{k+1} = x_k + f_k - (dX + dF) gamma,   gamma = argmin || f_k - dF gamma ||_2,
// the plain step from the combination of the recent iterates whose linearised update is smallest.
// On a linear f = A x + b it is equivalent to GMRES (Walker & Ni), so it converges without the
// symmetric Jacobian that an inertial relaxation (FIRE) or conjugate gradients need, in far fewer
// steps than the plain iteration when A's eigenvalues spread over decades.
#include <Eigen/Dense>

namespace bendlab {

class AndersonMixing {
 public:
  /// depth >= 1: the differences kept (Walker & Ni use 1-10; a deep history can make the nonlinear
  /// iteration less stable, not only dearer).
  explicit AndersonMixing(int depth);

  /// The step dx from x (the current iterate) and f (its plain update): f itself when there is no
  /// history, else the accelerated step above. x and f are recorded for the next call, whose x
  /// need not be x + dx (a caller may shorten the step; the history holds the steps taken).
  void step(const Eigen::VectorXd& x, const Eigen::VectorXd& f, Eigen::VectorXd& dx);

  /// Forget the history (the next step is the plain one).
  void reset();

  int history() const { return count_; }

 private:
  int depth_;
  Eigen::MatrixXd dx_, df_;  // ring buffers of columns
  Eigen::VectorXd x_prev_, f_prev_;
  int count_ = 0, next_ = 0;
  bool has_prev_ = false;
};

}  // namespace bendlab
