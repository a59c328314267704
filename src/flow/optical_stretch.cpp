#include "bendlab/flow/optical_stretch.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include "bendlab/geometry/measures.hpp"
#include "bendlab/integrate/anderson_mixing.hpp"

namespace bendlab {

namespace {

void require(bool ok, const std::string& message) {
  if (!ok) throw Error(message);
}

constexpr int kMaxRestarts = 8;
// Walker & Ni's range is 1-10. Measured on mt1:1280: M converges with 10; for D from 0 to 16 pN,
// 10 took 16593 steps, 30 took 7830, and 20 and 60 did not converge in 20000.
constexpr int kAndersonDepth = 10;

// The largest row length, without the overflow of a squared norm (a force of 1e308 pN has a
// length, not an infinite one).
double max_row_norm(const Points& a) {
  double largest = 0;
  for (Eigen::Index i = 0; i < a.rows(); ++i) {
    const double n = a.row(i).stableNorm();
    if (!(n <= largest)) largest = n;  // NaN is kept: a non-finite row is not hidden
  }
  return largest;
}

}  // namespace

StretchRelaxation default_relaxation(const std::string& method) {
  // M's linearised force is the one farthest from symmetric (docs/results/bending_stability.md), and
  // FIRE does not settle it at any force; D's and ED's are less so, and FIRE does better on them than
  // the overdamped relaxation (docs/results/rbc_stretch.md).
  return method == "M" ? StretchRelaxation::Overdamped : StretchRelaxation::Fire;
}

std::string to_string(StretchRelaxation r) {
  switch (r) {
    case StretchRelaxation::Fire: return "fire";
    case StretchRelaxation::Overdamped: return "overdamped";
    default: return "auto";
  }
}

nlohmann::json StretchSpec::to_json() const {
  const FireParameters& f = fire;
  nlohmann::json j = cell.to_json();
  const nlohmann::json own = {{"forces_pN", forces_pN},
                              {"fraction", fraction},
                              {"tolerance_pN", tolerance_pN},
                              {"max_iterations", max_iterations},
                              {"relaxation", to_string(relaxation)},
                              {"fire",
                               {{"n_min", f.n_min},
            {"f_inc", f.f_inc},
            {"f_dec", f.f_dec},
            {"alpha_start", f.alpha_start},
            {"f_alpha", f.f_alpha},
            {"dt_max_factor", f.dt_max_factor},
            {"dt_start_fraction", f.dt_start_fraction},
            {"max_step_edges", f.max_step_edges}}}};
  j.update(own);
  return j;
}

nlohmann::json StretchPoint::to_json() const {
  return {{"force_pN", force_pN},
          {"converged", converged},
          {"iterations", iterations},
          {"residual_pN", residual_pN},
          {"membrane_force_sum_pN", membrane_force_sum_pN},
          {"applied_force_sum_pN", applied_force_sum_pN},
          {"lambda_max", lambda_max},
          {"restarts", restarts},
          {"failure", failure.empty() ? nlohmann::json(nullptr) : nlohmann::json(failure)},
          {"axial_diameter_um", measures.axial_um},
          {"transverse_diameter_um", measures.transverse_um},
          {"extent_y_um", measures.extent_y_um},
          {"extent_z_um", measures.extent_z_um},
          {"area_um2", measures.area_um2},
          {"volume_um3", measures.volume_um3},
          {"area_change", area_change},
          {"volume_change", volume_change}};
}

void check_stretch(const StretchSpec& s) {
  check_cell_kind(s.cell);
  require(!s.forces_pN.empty(), "--forces: no force given");
  for (double f : s.forces_pN)
    require(std::isfinite(f) && f >= 0, fmt::format("--forces: {} pN is not a finite force >= 0", f));
  require(std::isfinite(s.fraction) && s.fraction > 0 && s.fraction <= 0.5,
          fmt::format("--fraction {} must lie in (0, 0.5] (the share of the vertices pulled at each end)", s.fraction));
  require(std::isfinite(s.tolerance_pN) && s.tolerance_pN > 0,
          fmt::format("--tolerance {} pN must be finite and positive", s.tolerance_pN));
  require(s.max_iterations > 0, fmt::format("--max-iterations {} must be positive", s.max_iterations));
}

int pulled_vertex_count(double fraction, int num_vertices) {
  const long n = std::lround(fraction * num_vertices);
  require(n > 0, fmt::format("--fraction {} selects no vertex of the {}-vertex mesh (round({} x {}) = 0)", fraction,
                             num_vertices, fraction, num_vertices));
  require(2 * n <= num_vertices, fmt::format("--fraction {} selects {} vertices at each end of a {}-vertex mesh: the "
                                             "two ends would share vertices",
                                             fraction, n, num_vertices));
  return static_cast<int>(n);
}

StretchMeasures stretch_measures(const Topology& topology, const Points& x) {
  StretchMeasures m;
  const Vec3 lo = x.colwise().minCoeff(), hi = x.colwise().maxCoeff();
  m.axial_um = hi.x() - lo.x();
  m.extent_y_um = hi.y() - lo.y();
  m.extent_z_um = hi.z() - lo.z();
  // The largest width of the projection onto the y-z plane over all directions u in that plane:
  // max_u (max_i p_i.u - min_j p_j.u) = max_{i,j} |p_i - p_j| (the Cauchy-Schwarz bound is met by
  // u along p_i - p_j).
  double best2 = 0;
  const Eigen::Index n = x.rows();
  for (Eigen::Index i = 0; i < n; ++i) {
    const double yi = x(i, 1), zi = x(i, 2);
    for (Eigen::Index j = i + 1; j < n; ++j) {
      const double dy = x(j, 1) - yi, dz = x(j, 2) - zi;
      best2 = std::max(best2, dy * dy + dz * dz);
    }
  }
  m.transverse_um = std::sqrt(best2);
  m.area_um2 = surface_area(topology, x);
  m.volume_um3 = enclosed_volume(topology, x);
  return m;
}

namespace {
StretchSpec checked(StretchSpec spec) {
  check_stretch(spec);
  return spec;
}
}  // namespace

OpticalStretch::OpticalStretch(StretchSpec spec)
    : spec_(checked(std::move(spec))),
      kind_(make_cell_kind(spec_.cell)),
      membrane_(physical_membrane(kind_)) {
  if (spec_.relaxation == StretchRelaxation::Auto)
    spec_.relaxation = default_relaxation(spec_.cell.bending_modulus > 0 ? spec_.cell.method : "none");
  const Points& ref = kind_.reference_um.positions();
  const int n_vertices = static_cast<int>(ref.rows());
  const int n = pulled_vertex_count(spec_.fraction, n_vertices);
  std::vector<int> order(n_vertices);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return ref(a, 0) < ref(b, 0); });
  left_.assign(order.begin(), order.begin() + n);
  // The largest x: from the end, so that ties go to the lower index here too.
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return ref(a, 0) > ref(b, 0); });
  right_.assign(order.begin(), order.begin() + n);
  x_ = ref;
  membrane_force_ = Points::Zero(n_vertices, 3);
  reference_measures_ = stretch_measures(membrane_->topology(), x_);
  mean_edge_um_ = kind_.mean_edge_um;
  // The membrane's stiffness at the reference shape sets the relaxation's step: moduli whose forces
  // overflow are refused here, before any output, with the options that set them.
  double lambda = 0;
  std::string why;
  try {
    lambda = estimate_lambda(Points::Zero(n_vertices, 3));
  } catch (const Error& e) {
    why = std::string(": ") + e.what();
  }
  if (!std::isfinite(lambda))
    throw Error(fmt::format("--shear-modulus {} N/m, --skalak-c {}, --bending-modulus {} J, --volume-ratio {}: the "
                            "membrane's forces are not finite numbers near its reference shape{} (a modulus beyond "
                            "what double precision can hold)",
                            spec_.cell.shear_modulus, spec_.cell.skalak_c, spec_.cell.bending_modulus,
                            spec_.cell.volume_modulus_ratio, why));
}

Points OpticalStretch::applied_forces(double force_pN) const {
  Points a = Points::Zero(x_.rows(), 3);
  const double per_vertex = force_pN / static_cast<double>(right_.size());
  for (int i : right_) a(i, 0) += per_vertex;
  for (int i : left_) a(i, 0) -= per_vertex;
  return a;
}

// The largest eigenvalue (in modulus) of the Jacobian of the membrane force at the current shape,
// by power iteration on finite differences: the stiffest mode sets FIRE's largest stable step.
double OpticalStretch::estimate_lambda(const Points& applied) {
  (void)applied;  // constant in x: no part of the Jacobian
  const Eigen::Index n = x_.rows();
  Points v(n, 3);
  for (Eigen::Index i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k) v(i, k) = std::sin(1.0 + 12.9898 * static_cast<double>(i) + 78.233 * k);
  Points f0, f1;
  membrane_->forces(x_, f0);
  const double h = 1e-6 * mean_edge_um_;
  double lambda = 0;
  for (int k = 0; k < 30; ++k) {
    v /= max_row_norm(v);
    membrane_->forces(x_ + h * v, f1);
    const Points jv = (f1 - f0) / h;
    const double ratio = jv.norm() / v.norm();
    // A force that overflows (moduli beyond double precision) has no stable step: say so rather
    // than keep the NaN out of the maximum and step blindly.
    if (!std::isfinite(ratio)) return std::numeric_limits<double>::infinity();
    lambda = std::max(lambda, ratio);
    if (!(jv.norm() > 0)) break;
    v = jv;
  }
  // Nothing stiff at all (no membrane force): any step is stable; keep a finite scale.
  return lambda > 0 ? lambda : 1.0;
}

StretchPoint OpticalStretch::equilibrate(double force_pN, const std::function<void(const std::string&)>& progress) {
  require(std::isfinite(force_pN) && force_pN >= 0, fmt::format("stretch force {} pN is not finite and >= 0", force_pN));
  const FireParameters& fp = spec_.fire;
  const Points applied = applied_forces(force_pN);
  const Eigen::Index n = x_.rows();
  StretchPoint p;
  p.force_pN = force_pN;
  p.applied_force_sum_pN = applied.colwise().sum().norm();

  Points r;
  auto evaluate = [&] {
    membrane_->forces(x_, membrane_force_);
    r = membrane_force_ + applied;
    return max_row_norm(r);
  };
  double residual = evaluate();
  const Points start = x_;
  long it = 0;
  if (residual >= spec_.tolerance_pN) {
    p.lambda_max = estimate_lambda(applied);
    double dt_max = fp.dt_max_factor / std::sqrt(p.lambda_max);
    const double max_step = fp.max_step_edges * mean_edge_um_;
    Points v = Points::Zero(n, 3), step(n, 3);
    double dt = fp.dt_start_fraction * dt_max, alpha = fp.alpha_start;
    double over_dt = fp.dt_max_factor / p.lambda_max;
    AndersonMixing mixing(kAndersonDepth);
    Eigen::VectorXd plain, flat, accelerated;
    double best_since_reset = residual;
    int positive = 0;
    long next_report = 20000;
    // A relaxation that overshoots may raise the residual for a while, never by orders of
    // magnitude: beyond this it diverges.
    const double blow_up = 1e3 * std::max(residual, spec_.tolerance_pN);
    while (residual >= spec_.tolerance_pN && it < spec_.max_iterations) {
      if (spec_.relaxation == StretchRelaxation::Overdamped) {
        // dx/dt = R by forward Euler: stable for dt |mu| < 2 on every eigenvalue mu of the
        // Jacobian with a negative real part; dt = dt_max_factor / lambda_max leaves a factor two.
        // Anderson mixing of the last steps (anderson_mixing.hpp) turns it into a GMRES-like solve;
        // a residual that has grown tenfold from the best since the last reset clears the history.
        if (residual > 10 * best_since_reset) {
          mixing.reset();
          best_since_reset = residual;
        }
        best_since_reset = std::min(best_since_reset, residual);
        plain = Eigen::Map<const Eigen::VectorXd>(r.data(), r.size()) * over_dt;
        flat = Eigen::Map<const Eigen::VectorXd>(x_.data(), x_.size());
        mixing.step(flat, plain, accelerated);
        step = Eigen::Map<const Points>(accelerated.data(), n, 3);
      } else {
      // FIRE (Bitzek et al. 2006): P = F.v decides whether to keep going downhill faster (mix the
      // velocity towards the force, grow dt) or to stop (v = 0, cut dt). v = 0 (the start, a
      // reset) has P = 0 and changes nothing.
      const double power = (r.array() * v.array()).sum();
      if (power > 0) {
        const double vn = v.norm(), fn = r.norm();
        if (fn > 0) v = (1 - alpha) * v + (alpha * vn / fn) * r;
        if (++positive > fp.n_min) {
          dt = std::min(dt * fp.f_inc, dt_max);
          alpha *= fp.f_alpha;
        }
      } else if (power < 0) {
        v.setZero();
        dt *= fp.f_dec;
        alpha = fp.alpha_start;
        positive = 0;
      }
      // Semi-implicit Euler with unit masses; the step bounded per vertex.
      v += dt * r;
      step = dt * v;
      }
      const double largest = max_row_norm(step);
      if (largest > max_step) {
        const double s = max_step / largest;
        step *= s;
        v *= s;
      }
      x_ += step;
      ++it;
      std::string failure;
      try {
        residual = evaluate();
        if (!(residual <= blow_up))
          failure = fmt::format("the residual grew to {:.3g} pN, a thousand times its start", residual);
      } catch (const Error& e) {
        failure = e.what();
      }
      if (!failure.empty()) {
        // A step too long for a stiff mode folded the mesh, made a force non-finite or set off a
        // growing oscillation: start the force again from its first shape with half the step.
        x_ = start;
        if (++p.restarts > kMaxRestarts) {
          p.failure = fmt::format("the relaxation diverged {} times, the time step halved each time (last: {})",
                                  p.restarts, failure);
          residual = evaluate();
          break;
        }
        v.setZero();
        dt_max *= 0.5;
        over_dt *= 0.5;
        mixing.reset();
        dt = fp.dt_start_fraction * dt_max;
        alpha = fp.alpha_start;
        positive = 0;
        residual = evaluate();
        best_since_reset = residual;
      }
      if (progress && it >= next_report) {
        progress(fmt::format("  F = {:g} pN: {} iterations, residual {:.3g} pN", force_pN, it, residual));
        next_report += 20000;
      }
    }
  }
  p.iterations = it;
  p.residual_pN = residual;
  p.converged = p.failure.empty() && residual < spec_.tolerance_pN;
  if (!p.converged && p.failure.empty())
    p.failure = fmt::format("the residual {:.3g} pN was above the tolerance {:g} pN after {} iterations{}", residual,
                            spec_.tolerance_pN, it,
                            p.restarts > 0 ? fmt::format(" ({} of them diverged and restarted with half the time step)",
                                                         p.restarts)
                                           : std::string());
  p.membrane_force_sum_pN = membrane_force_.colwise().sum().norm();
  p.measures = stretch_measures(membrane_->topology(), x_);
  p.area_change = p.measures.area_um2 / reference_measures_.area_um2 - 1;
  p.volume_change = p.measures.volume_um3 / reference_measures_.volume_um3 - 1;
  return p;
}

}  // namespace bendlab
