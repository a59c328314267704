#include "bendlab/integrate/rkc.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "bendlab/core/types.hpp"

namespace bendlab {

namespace {
// beta(s) ~ 0.653 s^2 for eps = 2/13 (Sommeijer et al., section 2.1): s stages are stable for
// h rho <= (s^2 - 1) / 1.54.
constexpr double kStabilityFactor = 1.54;

// A fixed, platform-independent start direction with every component present (a smooth start
// such as f(y) would hold little of the stiff modes the power iteration looks for).
void start_direction(Eigen::VectorXd& v, Eigen::Index n) {
  std::mt19937_64 gen(20261201);
  v.resize(n);
  for (Eigen::Index i = 0; i < n; ++i) v[i] = double(gen() >> 11) * 0x1.0p-53 - 0.5;
}
}  // namespace

Rkc::Rkc(RkcOptions options) : options_(std::move(options)) {
  const RkcOptions& o = options_;
  if (!(o.rtol >= 0) || !(o.atol >= 0) || o.rtol + o.atol <= 0)
    throw Error(fmt::format("RKC: tolerances must be non-negative and not both zero (rtol {}, atol {})", o.rtol, o.atol));
  if (o.max_stages < 2) throw Error(fmt::format("RKC: max_stages must be at least 2, got {}", o.max_stages));
  if (!(o.damping > 0) || !(o.damping < 1)) throw Error(fmt::format("RKC: damping must be in (0, 1), got {}", o.damping));
  if (!(o.spectral_safety >= 1)) throw Error(fmt::format("RKC: spectral_safety must be >= 1, got {}", o.spectral_safety));
  if (o.spectral_interval < 1) throw Error(fmt::format("RKC: spectral_interval must be >= 1, got {}", o.spectral_interval));
  if (o.spectral_max_iterations < 2)
    throw Error(fmt::format("RKC: spectral_max_iterations must be >= 2, got {}", o.spectral_max_iterations));
  if (!(o.reject_floor > 0) || !(o.reject_floor < 1))
    throw Error(fmt::format("RKC: reject_floor must be in (0, 1), got {}", o.reject_floor));
}

int Rkc::stages_for(double h, double rho) {
  const double s = 1.0 + std::floor(std::sqrt(1.0 + kStabilityFactor * h * std::max(rho, 0.0)));
  if (!(s < 1e9)) return 1'000'000'000;
  return std::max(2, static_cast<int>(s));
}

void Rkc::step(const Rhs& rhs, double t, const State& y, const State& fy, double h, int s, State& y1) {
  if (s < 2) throw Error(fmt::format("RKC: a step needs at least 2 stages, got {}", s));
  const Eigen::Index n = y.size();
  const double w0 = 1.0 + options_.damping / (double(s) * s);
  // T_j, T_j', T_j'' at w0 by the three-term recurrence T_j = 2 w0 T_{j-1} - T_{j-2}.
  std::vector<double> T(s + 1), dT(s + 1), d2T(s + 1);
  T[0] = 1, dT[0] = 0, d2T[0] = 0;
  T[1] = w0, dT[1] = 1, d2T[1] = 0;
  for (int j = 2; j <= s; ++j) {
    T[j] = 2 * w0 * T[j - 1] - T[j - 2];
    dT[j] = 2 * w0 * dT[j - 1] - dT[j - 2] + 2 * T[j - 1];
    d2T[j] = 2 * w0 * d2T[j - 1] - d2T[j - 2] + 4 * dT[j - 1];
  }
  const double w1 = dT[s] / d2T[s];
  auto b = [&](int j) { return j < 2 ? d2T[2] / (dT[2] * dT[2]) : d2T[j] / (dT[j] * dT[j]); };

  yjm2_ = y;
  yjm1_ = y + (h * b(1) * w1) * fy;  // Y_1
  fj_.resize(n);
  yj_.resize(n);
  double cjm2 = 0, cjm1 = b(1) * w1;  // c_0, c_1
  for (int j = 2; j <= s; ++j) {
    const double bj = b(j), bjm1 = b(j - 1), bjm2 = b(j - 2);
    const double mu = 2 * w0 * bj / bjm1;
    const double nu = -bj / bjm2;
    const double mus = 2 * w1 * bj / bjm1;
    const double ajm1 = 1 - bjm1 * T[j - 1];
    rhs(t + cjm1 * h, yjm1_, fj_);  // F_{j-1}
    yj_ = (1 - mu - nu) * y + mu * yjm1_ + nu * yjm2_ + (h * mus) * (fj_ - ajm1 * fy);
    const double cj = mu * cjm1 + nu * cjm2 + mus * (1 - ajm1);
    cjm2 = cjm1, cjm1 = cj;
    yjm2_.swap(yjm1_);
    yjm1_.swap(yj_);
  }
  y1 = yjm1_;
}

double Rkc::error_norm(const State& y, const State& y1, const State& est) const {
  double e = 0;
  const bool rms = options_.norm == RkcOptions::Norm::rms;
  for (Eigen::Index i = 0; i < y.size(); ++i) {
    const double scale = options_.atol + options_.rtol * std::max(std::abs(y[i]), std::abs(y1[i]));
    const double q = std::abs(est[i]) / scale;
    e = rms ? e + q * q : std::max(e, q);
  }
  if (rms && y.size() > 0) e = std::sqrt(e / double(y.size()));
  return std::isfinite(e) ? e : std::numeric_limits<double>::infinity();
}

double Rkc::estimate_spectral_radius(const Rhs& rhs, double t, const State& y, const State& fy,
                                     std::int64_t& evaluations, bool& converged) {
  const Eigen::Index n = y.size();
  if (v_.size() != n || !v_.allFinite() || v_.norm() == 0) start_direction(v_, n);
  const double ynorm = y.norm();
  const double delta = std::sqrt(std::numeric_limits<double>::epsilon()) * (ynorm > 0 ? ynorm : 1.0);
  pv_ = y + (delta / v_.norm()) * v_;
  pf_.resize(n);
  double rho = 0;
  converged = false;
  for (int it = 1; it <= options_.spectral_max_iterations; ++it) {
    rhs(t, pv_, pf_);
    ++evaluations;
    pf_ -= fy;  // f(v) - f(y)
    const double dfnorm = pf_.norm();
    const double previous = rho;
    // |v - y| is delta up to rounding; dividing by the actual difference keeps the ratio exact.
    rho = dfnorm / (pv_ - y).norm();
    if (!std::isfinite(rho)) throw Error(fmt::format("RKC: the spectral radius estimate is not finite at t = {}", t));
    if (it >= 2 && std::abs(rho - previous) <= options_.spectral_tolerance * rho) {
      converged = true;
      v_ = pv_ - y;
      break;
    }
    if (dfnorm > 0) {
      v_ = pf_;
    } else {  // f is locally constant along v: turn one component around, as the RKC code does
      v_ = pv_ - y;
      const Eigen::Index k = it % n;
      v_[k] = -v_[k];
    }
    pv_ = y + (delta / v_.norm()) * v_;
  }
  if (!converged) v_ = pv_ - y;
  return rho;
}

void Rkc::update_spectral_radius(const Rhs& rhs, double t, const State& y, const State& fy) {
  ++stats_.spectral_estimates;
  if (options_.spectral_radius) {
    rho_ = options_.spectral_radius(t, y);
    if (!(rho_ >= 0) || !std::isfinite(rho_))
      throw Error(fmt::format("RKC: the spectral radius function returned {} at t = {}", rho_, t));
  } else {
    std::int64_t evals = 0;
    bool converged = false;
    rho_ = options_.spectral_safety * estimate_spectral_radius(rhs, t, y, fy, evals, converged);
    stats_.spectral_evaluations += evals;
    stats_.rhs_evaluations += evals;
    if (!converged) ++stats_.spectral_unconverged;
  }
  stats_.spectral_radius = rho_;
  stats_.spectral_radius_max = std::max(stats_.spectral_radius_max, rho_);
  since_estimate_ = 0;
}

RkcCheckpoint Rkc::checkpoint() const {
  RkcCheckpoint c;
  c.dt_next = proposed_;
  c.err_previous = err_prev_;
  c.dt_previous = dt_prev_;
  c.after_rejection = after_rejection_;
  c.spectral_radius = rho_;
  c.spectral_vector = v_;
  c.steps_since_estimate = since_estimate_;
  return c;
}

void Rkc::restore(const RkcCheckpoint& c) {
  if (!(c.dt_next >= 0) || !(c.spectral_radius >= 0) || c.steps_since_estimate < 0)
    throw Error("RKC: invalid checkpoint (negative step, spectral radius or step count)");
  proposed_ = c.dt_next;
  err_prev_ = c.err_previous;
  dt_prev_ = c.dt_previous;
  after_rejection_ = c.after_rejection;
  rho_ = c.spectral_radius;
  v_ = c.spectral_vector;
  since_estimate_ = c.steps_since_estimate;
  restored_totals_ = Totals{};
  restored_ = true;
}

nlohmann::json Rkc::summary() const {
  const std::int64_t steps = before_.steps + stats_.accepted + stats_.rejected;
  const std::int64_t stages = before_.stages + stats_.stages;
  return {{"steps_with_rejected", steps},
          {"mean_stages", steps > 0 ? double(stages) / double(steps) : 0.0},
          {"max_stages", std::max(before_.max_stages, stats_.max_stages_used)},
          {"spectral_radius", rho_},
          {"spectral_radius_max", std::max(before_.rho_max, stats_.spectral_radius_max)},
          {"spectral_evaluations", before_.spectral_evaluations + stats_.spectral_evaluations},
          {"stages_total", stages}};
}

nlohmann::json Rkc::checkpoint_state() const {
  const RkcCheckpoint c = checkpoint();
  const nlohmann::json totals = summary();
  return {{"dt_next", c.dt_next},
          {"err_previous", c.err_previous},
          {"dt_previous", c.dt_previous},
          {"after_rejection", c.after_rejection},
          {"spectral_radius", c.spectral_radius},
          {"spectral_vector", std::vector<double>(c.spectral_vector.data(), c.spectral_vector.data() + c.spectral_vector.size())},
          {"steps_since_estimate", c.steps_since_estimate},
          {"totals", {{"steps", totals.at("steps_with_rejected")},
                      {"stages", totals.at("stages_total")},
                      {"spectral_evaluations", totals.at("spectral_evaluations")},
                      {"max_stages", totals.at("max_stages")},
                      {"spectral_radius_max", totals.at("spectral_radius_max")}}}};
}

void Rkc::restore_checkpoint_state(const nlohmann::json& j, const std::string& source) {
  auto number = [&](const nlohmann::json& o, const char* key) {
    if (!o.is_object() || !o.contains(key) || !o.at(key).is_number() || !std::isfinite(o.at(key).get<double>()))
      throw Error(fmt::format("{}: RKC state: \"{}\" must be a finite number", source, key));
    return o.at(key).get<double>();
  };
  RkcCheckpoint c;
  c.dt_next = number(j, "dt_next");
  c.err_previous = number(j, "err_previous");
  c.dt_previous = number(j, "dt_previous");
  if (!j.contains("after_rejection") || !j.at("after_rejection").is_boolean())
    throw Error(fmt::format("{}: RKC state: \"after_rejection\" must be true or false", source));
  c.after_rejection = j.at("after_rejection").get<bool>();
  c.spectral_radius = number(j, "spectral_radius");
  c.steps_since_estimate = static_cast<int>(number(j, "steps_since_estimate"));
  if (!j.contains("spectral_vector") || !j.at("spectral_vector").is_array())
    throw Error(fmt::format("{}: RKC state: \"spectral_vector\" must be an array of numbers", source));
  const auto& v = j.at("spectral_vector");
  c.spectral_vector.resize(static_cast<Eigen::Index>(v.size()));
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (!v[i].is_number()) throw Error(fmt::format("{}: RKC state: \"spectral_vector\" must be an array of numbers", source));
    c.spectral_vector[static_cast<Eigen::Index>(i)] = v[i].get<double>();
  }
  if (!j.contains("totals")) throw Error(fmt::format("{}: RKC state: \"totals\" missing", source));
  const auto& t = j.at("totals");
  Totals totals;
  totals.steps = static_cast<std::int64_t>(number(t, "steps"));
  totals.stages = static_cast<std::int64_t>(number(t, "stages"));
  totals.spectral_evaluations = static_cast<std::int64_t>(number(t, "spectral_evaluations"));
  totals.max_stages = static_cast<int>(number(t, "max_stages"));
  totals.rho_max = number(t, "spectral_radius_max");
  restore(c);  // checks the ranges
  restored_totals_ = totals;
}

IntegratorStats Rkc::integrate(const Rhs& rhs, double t0, double t1, State& y, double dt0, const OnAccept& on_accept) {
  if (!(t1 > t0)) throw Error(fmt::format("RKC: end time {} must be after start time {}", t1, t0));
  const RkcOptions& o = options_;
  stats_ = RkcStats{};
  stats_.t = t0;
  double dt;
  if (restored_ && (dt0 > 0 || proposed_ > 0)) {
    dt = dt0 > 0 ? dt0 : proposed_;
  } else {
    dt = dt0 > 0 ? dt0 : o.dt_initial;
  }
  before_ = restored_ ? restored_totals_ : Totals{};
  restored_totals_ = Totals{};
  if (!restored_) {  // a fresh integration
    err_prev_ = dt_prev_ = 0;
    after_rejection_ = false;
    rho_ = 0;
    since_estimate_ = 0;
  }
  restored_ = false;
  dt = std::min(dt, o.dt_max);
  proposed_ = dt;
  const Eigen::Index n = y.size();
  f0_.resize(n);
  f1_.resize(n);
  rhs(t0, y, f0_);
  ++stats_.rhs_evaluations;
  bool estimated_here = false;  // the spectral radius was estimated at the current (t, y)
  bool estimate_due = rho_ <= 0 || since_estimate_ >= o.spectral_interval;
  const double eps_t = 64 * std::numeric_limits<double>::epsilon() * std::max(std::abs(t0), std::abs(t1));
  while (t1 - stats_.t > eps_t) {
    if (stats_.accepted + stats_.rejected >= o.max_steps)
      throw Error(fmt::format("RKC: more than {} steps before t = {} (reached t = {})", o.max_steps, t1, stats_.t));
    if (estimate_due && !estimated_here) {
      update_spectral_radius(rhs, stats_.t, y, f0_);
      estimated_here = true;
    }
    estimate_due = false;
    bool last = stats_.t + dt >= t1;
    double h = last ? t1 - stats_.t : dt;
    int s = stages_for(h, rho_);
    if (s > o.max_stages) {
      s = o.max_stages;
      h = (double(s) * s - 1) / (kStabilityFactor * rho_);
      last = false;
      ++stats_.stage_capped_steps;
    }
    stats_.stages += s;
    stats_.max_stages_used = std::max(stats_.max_stages_used, s);
    step(rhs, stats_.t, y, f0_, h, s, y1_);
    rhs(stats_.t + h, y1_, f1_);
    stats_.rhs_evaluations += s;  // s - 1 stages and F(y_{n+1})
    double e = 0;
    if (o.adaptive) {
      est_ = 0.8 * (y - y1_) + (0.4 * h) * (f0_ + f1_);
      e = error_norm(y, y1_, est_);
    }
    if (!o.adaptive || e <= 1.0) {
      stats_.t = last ? t1 : stats_.t + h;
      ++stats_.accepted;
      double next = dt;
      if (o.adaptive) {
        double fac;
        if (e <= 0) {
          fac = o.grow;
        } else if (err_prev_ > 0 && dt_prev_ > 0 && !after_rejection_) {
          fac = o.safety * (h / dt_prev_) * std::cbrt(err_prev_) / std::pow(e, 2.0 / 3.0);
        } else {
          fac = o.safety / std::cbrt(e);
        }
        fac = std::min(fac, after_rejection_ ? 1.0 : o.grow);
        next = h * std::max(fac, o.shrink);
        err_prev_ = std::max(e, 1e-10);
        dt_prev_ = h;
        // As Cash-Karp: a last step shortened to land on t1 does not shrink the proposal.
        if (last) next = std::max(next, dt);
      }
      after_rejection_ = false;
      dt = std::min(next, o.dt_max);
      stats_.dt_next = proposed_ = dt;
      y.swap(y1_);
      f0_.swap(f1_);  // F(y_{n+1}): the next step's first stage
      ++since_estimate_;
      estimated_here = false;
      estimate_due = since_estimate_ >= o.spectral_interval;
      if (on_accept) {
        ysave_ = y;
        const bool go = on_accept(stats_.t, h, y);
        if (y.size() != n) throw Error(fmt::format("RKC: on_accept changed the state size from {} to {}", n, y.size()));
        const bool modified = !(y.array() == ysave_.array()).all();
        if (modified && !o.reuse_f_after_modification) {
          rhs(stats_.t, y, f0_);
          ++stats_.rhs_evaluations;
        } else {
          ++stats_.fsal_reused;
        }
        if (!go) {
          stats_.stopped = true;
          return stats_;
        }
      } else {
        ++stats_.fsal_reused;
      }
    } else {
      ++stats_.rejected;
      after_rejection_ = true;
      const double fac = std::isfinite(e) ? o.safety / std::cbrt(e) : o.reject_floor;
      dt = proposed_ = h * std::max(fac, o.reject_floor);
      estimate_due = true;  // skipped when the estimate is already of this (t, y)
      if (dt < o.dt_min)
        throw Error(fmt::format("RKC: step size {:.3e} below the minimum {:.3e} at t = {} (error norm {:.3e}); "
                                "the state is no longer finite or the spectral radius is underestimated",
                                dt, o.dt_min, stats_.t, e));
    }
  }
  stats_.dt_next = dt;
  return stats_;
}

}  // namespace bendlab
