// The second-order Runge-Kutta-Chebyshev integrator (rkc.hpp): stability polynomial, orders,
// stage counts, spectral radius, on_accept modifications, checkpoints, a nonlinear stiff problem.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <vector>

#include <Eigen/Eigenvalues>

#include "bendlab/core/types.hpp"
#include "bendlab/integrate/cash_karp.hpp"
#include "bendlab/integrate/rkc.hpp"

using namespace bendlab;
using State = Rkc::State;

namespace {

// Second differences on n interior points of [0, 1] with zero ends, times nu:
// eigenvalues -4 nu (n+1)^2 sin^2(k pi / (2 (n+1))), k = 1..n, eigenvectors sin(k pi x_j).
Eigen::MatrixXd diffusion_matrix(int n, double nu) {
  const double c = nu * (n + 1.0) * (n + 1.0);
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(n, n);
  for (int i = 0; i < n; ++i) {
    A(i, i) = -2 * c;
    if (i > 0) A(i, i - 1) = c;
    if (i + 1 < n) A(i, i + 1) = c;
  }
  return A;
}
double diffusion_radius(int n, double nu) {
  const double s = std::sin(n * M_PI / (2.0 * (n + 1)));
  return 4 * nu * (n + 1.0) * (n + 1.0) * s * s;
}
// exp(A t) y0 for symmetric A.
State exact_linear(const Eigen::MatrixXd& A, const State& y0, double t) {
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(A);
  const Eigen::VectorXd g = (es.eigenvalues() * t).array().exp();
  return es.eigenvectors() * (g.asDiagonal() * (es.eigenvectors().transpose() * y0));
}
Rkc::Rhs linear_rhs(const Eigen::MatrixXd& A) {
  return [A](double, const State& y, State& d) { d.noalias() = A * y; };
}
// A smooth start with every mode present: x (1 - x) plus a small rough part.
State smooth_start(int n) {
  State y(n);
  for (int j = 0; j < n; ++j) {
    const double x = (j + 1.0) / (n + 1);
    y[j] = x * (1 - x) + 1e-3 * ((j % 3) - 1.0);
  }
  return y;
}

}  // namespace

TEST(Rkc, StabilityPolynomialBoundedOnTheStabilityInterval) {
  // One step of y' = lambda y with h = 1 gives R(lambda). s stages promise |R(z)| <= 1 for
  // z in [-(s^2 - 1)/1.54, 0] (stages_for), and R(z) = 1 + z + z^2/2 + O(z^3) (second order).
  for (int s : {2, 3, 5, 10, 40, 250}) {
    Rkc rkc;
    const double zmax = (double(s) * s - 1) / 1.54;
    double worst = 0;
    for (int k = 0; k <= 2000; ++k) {
      const double z = -zmax * k / 2000.0;
      const Rkc::Rhs f = [z](double, const State& y, State& d) { d = z * y; };
      State y(1), fy(1), y1;
      y << 1.0;
      fy << z;
      rkc.step(f, 0.0, y, fy, 1.0, s, y1);
      worst = std::max(worst, std::abs(y1[0]));
    }
    EXPECT_LE(worst, 1.0 + 1e-12) << "s = " << s;
    // Local error of R(z) against e^z for small z: O(z^3).
    double e[2];
    for (int k = 0; k < 2; ++k) {
      const double z = -1e-2 / (1 << k);
      const Rkc::Rhs f = [z](double, const State& y, State& d) { d = z * y; };
      State y(1), fy(1), y1;
      y << 1.0;
      fy << z;
      rkc.step(f, 0.0, y, fy, 1.0, s, y1);
      e[k] = std::abs(y1[0] - std::exp(z));
    }
    EXPECT_NEAR(std::log2(e[0] / e[1]), 3.0, 0.1) << "s = " << s;
  }
  EXPECT_EQ(Rkc::stages_for(0.0, 1e4), 2);
  EXPECT_EQ(Rkc::stages_for(1.0, 0.0), 2);
  EXPECT_EQ(Rkc::stages_for(100.0, 100.0), 1 + static_cast<int>(std::sqrt(1 + 1.54e4)));
}

TEST(Rkc, SecondOrderAtFixedStepOnStiffDiffusion) {
  // Eigenvalues from about -0.62 to -1e4; the exact solution by eigen-decomposition. The start holds
  // the two slowest modes (h lambda <= 0.25 for them): the global error is the second-order error of
  // smooth modes, while the stiff end (h rho up to 1e3, s up to 42 stages) must stay stable.
  const int n = 199;
  const double nu = 1e4 / (4.0 * 200 * 200);
  const Eigen::MatrixXd A = diffusion_matrix(n, nu);
  State y0(n);
  for (int j = 0; j < n; ++j) {
    const double x = (j + 1.0) / (n + 1);
    y0[j] = std::sin(M_PI * x) + 0.5 * std::sin(2 * M_PI * x);
  }
  const double T = 1.0;
  const State exact = exact_linear(A, y0, T);
  double prev = 0;
  int prev_stages = 0;
  for (double h : {0.1, 0.05, 0.025, 0.0125}) {
    RkcOptions o;
    o.adaptive = false;
    Rkc rkc(o);
    State y = y0;
    const IntegratorStats st = rkc.integrate(linear_rhs(A), 0.0, T, y, h);
    EXPECT_NEAR(st.t, T, 1e-13);
    EXPECT_NEAR(double(st.accepted), T / h, 1.0);
    const double err = (y - exact).lpNorm<Eigen::Infinity>();
    std::printf("[RKC2 fixed step, diffusion rho = 1e4] h %.4f error %.3e stages %d rho estimate %.4g\n", h, err,
                rkc.stats().max_stages_used, rkc.stats().spectral_radius);
    if (prev > 0) {
      EXPECT_NEAR(std::log2(prev / err), 2.0, 0.25) << h;
      // Stages ~ sqrt(h rho): halving h divides s by about sqrt(2).
      EXPECT_NEAR(double(prev_stages) / rkc.stats().max_stages_used, std::sqrt(2.0), 0.15) << h;
    }
    prev = err;
    prev_stages = rkc.stats().max_stages_used;
    // The power iteration brackets the spectral radius: at most the safety factor above it.
    EXPECT_GT(rkc.stats().spectral_radius, 0.97 * diffusion_radius(n, nu));
    EXPECT_LT(rkc.stats().spectral_radius, 1.1 * diffusion_radius(n, nu) * (1 + 1e-9));
  }
}

TEST(Rkc, AdaptiveErrorFallsWithTolerance) {
  const int n = 99;
  const double nu = 1e4 / (4.0 * 100 * 100);
  const Eigen::MatrixXd A = diffusion_matrix(n, nu);
  const State y0 = smooth_start(n);
  const State exact = exact_linear(A, y0, 1.0);
  double prev_err = 0;
  std::int64_t prev_steps = 0;
  for (double tol : {1e-3, 1e-4, 1e-5, 1e-6, 1e-7}) {
    RkcOptions o;
    o.rtol = o.atol = tol;
    Rkc rkc(o);
    State y = y0;
    const IntegratorStats st = rkc.integrate(linear_rhs(A), 0.0, 1.0, y);
    const double err = (y - exact).lpNorm<Eigen::Infinity>();
    EXPECT_LT(err, 20 * tol) << tol;
    if (prev_err > 0) {
      EXPECT_LT(err, prev_err) << tol;
      EXPECT_GT(st.accepted, prev_steps) << tol;
    }
    // Evaluations: stages, the final F(y) of every step, the first f, the power iterations.
    const RkcStats& rs = rkc.stats();
    EXPECT_EQ(rs.rhs_evaluations, rs.stages + 1 + rs.spectral_evaluations);
    EXPECT_EQ(rs.fsal_reused, rs.accepted);
    prev_err = err;
    prev_steps = st.accepted;
  }
}

TEST(Rkc, StageCountFollowsSqrtOfStepTimesSpectralRadius) {
  // With the exact spectral radius supplied, s = 1 + floor(sqrt(1 + 1.54 h rho)) exactly.
  const int n = 49;
  for (double nu : {0.1, 0.4, 1.6}) {
    const Eigen::MatrixXd A = diffusion_matrix(n, nu);
    const double rho = diffusion_radius(n, nu);
    RkcOptions o;
    o.adaptive = false;
    o.spectral_radius = [rho](double, const State&) { return rho; };
    Rkc rkc(o);
    State y = smooth_start(n);
    const double h = 0.02;
    rkc.integrate(linear_rhs(A), 0.0, 0.2, y, h);
    const RkcStats& st = rkc.stats();
    EXPECT_EQ(st.max_stages_used, Rkc::stages_for(h, rho));
    EXPECT_EQ(st.spectral_evaluations, 0);
    EXPECT_EQ(st.spectral_estimates, 1);
  }
  // The cap: a step needing more stages is shortened to what max_stages allows.
  const Eigen::MatrixXd A = diffusion_matrix(n, 1.6);
  const double rho = diffusion_radius(n, 1.6);
  RkcOptions o;
  o.adaptive = false;
  o.max_stages = 10;
  o.spectral_radius = [rho](double, const State&) { return rho; };
  Rkc rkc(o);
  State y = smooth_start(n);
  rkc.integrate(linear_rhs(A), 0.0, 0.1, y, 0.1);
  EXPECT_EQ(rkc.stats().max_stages_used, 10);
  EXPECT_GT(rkc.stats().stage_capped_steps, 0);
  EXPECT_GE(rkc.stats().accepted, std::int64_t(std::ceil(0.1 * 1.54 * rho / 99)));
  EXPECT_TRUE(y.allFinite());
  EXPECT_LT(y.lpNorm<Eigen::Infinity>(), 1.0);
}

TEST(Rkc, PowerIterationFindsSpectralRadius) {
  // A symmetric negative definite matrix with known eigenvalues in [-5000, -1], two near the top,
  // in a random orthogonal basis; f(y) = A y + a nonlinearity that is flat near y (so the
  // differences see A).
  const int n = 80;
  Eigen::VectorXd lam(n);
  for (int k = 0; k < n; ++k) lam[k] = -(1.0 + 4999.0 * std::pow(double(k) / (n - 1), 2.0));
  lam[n - 2] = -4900;
  std::srand(7);
  const Eigen::MatrixXd Q = Eigen::HouseholderQR<Eigen::MatrixXd>(Eigen::MatrixXd::Random(n, n)).householderQ();
  const Eigen::MatrixXd A = Q * lam.asDiagonal() * Q.transpose();
  const Rkc::Rhs f = [&](double, const State& y, State& d) {
    d.noalias() = A * y;
    d.array() += 1e-3 * y.array().cube();
  };
  State y = State::Constant(n, 0.1), fy(n);
  f(0.0, y, fy);
  Rkc rkc;
  std::int64_t evals = 0;
  bool converged = false;
  const double rho = rkc.estimate_spectral_radius(f, 0.0, y, fy, evals, converged);
  EXPECT_TRUE(converged);
  // |f(v) - f(y)| / |v - y| <= rho for symmetric A (up to the small nonlinearity): from below, within
  // 5% when the iteration stops on a 1% change (the top two eigenvalues are 2% apart).
  EXPECT_LE(rho, 5000.0 * 1.001);
  EXPECT_GE(rho, 5000.0 * 0.95);
  EXPECT_LE(evals, 50);
  // Warm start from the stored vector: few iterations the second time.
  std::int64_t evals2 = 0;
  const double rho2 = rkc.estimate_spectral_radius(f, 0.0, y, fy, evals2, converged);
  EXPECT_LE(rho2, 5000.0 * 1.001);
  EXPECT_GE(rho2, rho);
  EXPECT_LT(evals2, evals);
}

namespace {
// A stiff linear system whose on_accept modifies the state: it puts back the total (sum y), which
// the rhs f(y) = A y + source does not conserve.
struct ModifiedProblem {
  Eigen::MatrixXd A = diffusion_matrix(30, 0.5);
  double total = 0;
  Rkc::Rhs rhs = [this](double t, const State& y, State& d) {
    d.noalias() = A * y;
    d.array() += std::sin(3 * t);
  };
  Rkc::OnAccept project = [this](double, double, State& y) {
    y.array() += (total - y.sum()) / double(y.size());
    return true;
  };
  State start() {
    State y = smooth_start(30);
    total = y.sum();
    return y;
  }
};
}  // namespace

TEST(Rkc, ModificationInOnAcceptReevaluatesFirstStageAndResumesIdentically) {
  RkcOptions o;
  o.rtol = o.atol = 1e-4;
  o.spectral_interval = 5;
  ModifiedProblem p;
  // Uninterrupted run.
  State y_full = p.start();
  Rkc full(o);
  full.integrate(p.rhs, 0.0, 1.0, y_full, 0.0, p.project);
  const RkcStats st = full.stats();
  ASSERT_GT(st.accepted, 10);
  EXPECT_EQ(st.fsal_reused, 0);  // every step modified y, so f was evaluated again
  EXPECT_EQ(st.rhs_evaluations, st.stages + 1 + st.accepted + st.spectral_evaluations);
  EXPECT_NEAR(y_full.sum(), p.total, 1e-12);
  // The same run stopped after every accepted step and resumed from the checkpoint by a new
  // integrator, which starts each piece with a fresh f(y): identical bit for bit only if the
  // uninterrupted run evaluated f at the modified state.
  State y = p.start();
  double t = 0;
  RkcCheckpoint c;
  bool have = false;
  int pieces = 0;
  while (t < 1.0 && pieces < 100000) {
    Rkc piece(o);
    if (have) piece.restore(c);
    piece.integrate(p.rhs, t, 1.0, y, 0.0, [&](double tn, double dt, State& s) {
      p.project(tn, dt, s);
      t = tn;
      c = piece.checkpoint();
      return false;
    });
    have = true;
    ++pieces;
  }
  EXPECT_EQ(pieces, st.accepted);
  EXPECT_EQ((y - y_full).lpNorm<Eigen::Infinity>(), 0.0);
  // Keeping the stale F(y_{n+1}) saves one evaluation per step but changes the result.
  RkcOptions stale = o;
  stale.reuse_f_after_modification = true;
  Rkc r(stale);
  State y_stale = p.start();
  r.integrate(p.rhs, 0.0, 1.0, y_stale, 0.0, p.project);
  EXPECT_EQ(r.stats().fsal_reused, r.stats().accepted);
  EXPECT_GT((y_stale - y_full).lpNorm<Eigen::Infinity>(), 0.0);
  EXPECT_LT((y_stale - y_full).lpNorm<Eigen::Infinity>(), 1e-3);
}

TEST(Rkc, CallbackStopsAndCommonInterface) {
  std::vector<std::unique_ptr<Integrator>> methods;
  methods.push_back(std::make_unique<CashKarp>());
  methods.push_back(std::make_unique<Rkc>());
  for (auto& m : methods) {
    State y(1);
    y << 1.0;
    const IntegratorStats st = m->integrate([](double, const State& s, State& d) { d = -s; }, 0.0, 10.0, y, 0.0,
                                            [](double t, double, State&) { return t < 1.0; });
    EXPECT_TRUE(st.stopped) << m->name();
    EXPECT_GE(st.t, 1.0) << m->name();
    // Local errors of at most about atol + rtol |y| = 1.1e-6 per step add up.
    EXPECT_NEAR(y[0], std::exp(-st.t), 1.1e-6 * double(st.accepted)) << m->name();
    EXPECT_EQ(st.dt_next, m->proposed_step()) << m->name();
  }
  EXPECT_EQ(methods[1]->name(), "rkc");
  RkcOptions zero;
  zero.rtol = zero.atol = 0;
  EXPECT_THROW(Rkc{zero}, Error);
  State y(1);
  y << 1.0;
  EXPECT_THROW(Rkc().integrate([](double, const State& s, State& d) { d = -s; }, 1.0, 1.0, y), Error);
}

namespace {
// The Brusselator with diffusion (Hairer & Wanner, Solving ODEs II, section IV.1) on n interior
// points of [0, 1]: u' = 1 + u^2 v - 4.4 u + alpha u_xx, v' = 3.4 u - u^2 v + alpha v_xx, with
// u = 1, v = 3 at both ends. Stiffness from diffusion: rho ~ 4 alpha (n + 1)^2 ~ 3e3.
constexpr int kBn = 200;
constexpr double kAlpha = 0.02;
void brusselator(double, const State& y, State& d) {
  const double c = kAlpha * (kBn + 1.0) * (kBn + 1.0);
  for (int i = 0; i < kBn; ++i) {
    const double u = y[2 * i], v = y[2 * i + 1];
    const double ul = i > 0 ? y[2 * i - 2] : 1.0, ur = i + 1 < kBn ? y[2 * i + 2] : 1.0;
    const double vl = i > 0 ? y[2 * i - 1] : 3.0, vr = i + 1 < kBn ? y[2 * i + 3] : 3.0;
    d[2 * i] = 1 + u * u * v - 4.4 * u + c * (ul - 2 * u + ur);
    d[2 * i + 1] = 3.4 * u - u * u * v + c * (vl - 2 * v + vr);
  }
}
State brusselator_start() {
  State y(2 * kBn);
  for (int i = 0; i < kBn; ++i) {
    const double x = (i + 1.0) / (kBn + 1);
    y[2 * i] = 1 + std::sin(2 * M_PI * x);
    y[2 * i + 1] = 3;
  }
  return y;
}
}  // namespace

TEST(Rkc, NonlinearStiffBrusselatorAgainstCashKarp) {
  const double T = 2.0;
  CashKarpOptions co;
  co.rtol = co.atol = 1e-10;
  State ref = brusselator_start();
  CashKarp ck(co);
  ck.integrate(brusselator, 0.0, T, ref);
  double prev = 0;
  for (double tol : {1e-4, 1e-6}) {
    RkcOptions o;
    o.rtol = o.atol = tol;
    Rkc rkc(o);
    State y = brusselator_start();
    rkc.integrate(brusselator, 0.0, T, y);
    const double err = (y - ref).lpNorm<Eigen::Infinity>();
    EXPECT_LT(err, 50 * tol) << tol;
    if (prev > 0) {
      EXPECT_LT(err, prev / 10) << tol;
    }
    prev = err;
    // The estimate finds the diffusion's spectral radius (about 4 alpha (n + 1)^2 = 3232) within
    // the safety factor.
    EXPECT_GT(rkc.stats().spectral_radius_max, 0.97 * 3232);
    EXPECT_LT(rkc.stats().spectral_radius_max, 1.15 * 3232);
    // Cash-Karp at the same tolerance is held to h rho <~ 3.3 by stability.
    CashKarpOptions c2;
    c2.rtol = c2.atol = tol;
    CashKarp ck2(c2);
    State y2 = brusselator_start();
    const IntegratorStats cst = ck2.integrate(brusselator, 0.0, T, y2);
    EXPECT_LT(rkc.stats().rhs_evaluations, cst.rhs_evaluations) << tol;
  }
}
