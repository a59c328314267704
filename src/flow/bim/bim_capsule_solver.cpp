#include "bendlab/flow/bim/bim_capsule_solver.hpp"

#include <fmt/format.h>

#include <cmath>
#include <limits>

#include "bendlab/core/finite_check.hpp"
#include "bendlab/flow/volume_correction.hpp"
#include "bendlab/geometry/measures.hpp"
#include "bendlab/integrate/cash_karp.hpp"

namespace bendlab {

namespace {
const std::shared_ptr<const MembraneModel>& checked(const std::shared_ptr<const MembraneModel>& m,
                                                    const BimOptions& o) {
  if (m == nullptr) throw Error("BIM: no membrane model");
  if (!(o.mu > 0) || !std::isfinite(o.mu)) throw Error(fmt::format("BIM: mu must be positive, got {}", o.mu));
  if (!(o.gamma > 0) || !std::isfinite(o.gamma))
    throw Error(fmt::format("BIM: gamma must be positive, got {}", o.gamma));
  return m;
}

Points centred(const MembraneModel& m) {
  Points x = m.initial_positions();
  x.rowwise() -= volume_centroid(m.topology(), x).transpose();
  return x;
}
}  // namespace

BimCapsuleSolver::BimCapsuleSolver(std::shared_ptr<const MembraneModel> membrane,
                                   std::unique_ptr<Integrator> integrator, BimOptions options)
    : membrane_(checked(membrane, options)),
      integrator_(integrator ? std::move(integrator) : std::make_unique<CashKarp>()),
      options_(options),
      single_layer_(membrane_->topology_ptr(), options.quadrature),
      x_(centred(*membrane_)) {}

void BimCapsuleSolver::restart(const Points& positions, double time, double dt_next) {
  const int n = membrane_->num_vertices();
  if (positions.rows() != n) throw Error(fmt::format("BIM restart: {} positions for {} vertices", positions.rows(), n));
  if (!positions.allFinite()) throw Error("BIM restart: positions are not finite");
  if (!std::isfinite(time) || time < 0) throw Error(fmt::format("BIM restart: invalid time {}", time));
  x_ = positions;
  t_ = time;
  dt_next_ = dt_next > 0 ? dt_next : 0;
  integrator_resume_ = nullptr;
  integrator_continues_ = false;
}

void BimCapsuleSolver::velocity(const Points& x, Points& u) {
  membrane_->force_density(x, density_);  // checks positions and every force stage
  single_layer_.velocity(x, density_, options_.mu, u);
  u.col(0) += options_.gamma * x.col(2);  // u_inf = gamma z e_x
  require_finite_rows(u, "BIM: the single-layer velocity");
  volume_gradient(membrane_->topology(), x, grad_);
  project_zero_flux(grad_, u);
  ++counters_.velocity_evaluations;
}

bool BimCapsuleSolver::advance(double t_end, const OnStep& on_step) {
  if (!(t_end > t_)) return true;
  const int n = membrane_->num_vertices();
  const Topology& topology = membrane_->topology();
  const double volume0 = membrane_->initial_volume();
  const std::int64_t rejected_before = counters_.rejected_steps;
  // The state vector is the row-major N x 3 position array, flattened.
  Eigen::VectorXd y = Eigen::Map<const Eigen::VectorXd>(x_.data(), 3 * n);
  // A non-finite value at an accepted state (the first stage of a step, t == t_) cannot be cured
  // by a smaller step: the run stops with the diagnosis, the time and the step. At a trial stage
  // (t > t_) it only says that the trial step was too large: the stage returns NaN, so that the
  // integrator rejects the step and tries a smaller one.
  auto rhs = [&](double t, const Eigen::VectorXd& state, Eigen::VectorXd& dydt) {
    xb_ = Eigen::Map<const Points>(state.data(), n, 3);
    try {
      velocity(xb_, u_);
    } catch (const NonFiniteError& e) {
      if (t > t_) {
        dydt.setConstant(std::numeric_limits<double>::quiet_NaN());
        return;
      }
      throw NonFiniteError(fmt::format("{} at gamma t = {:.6g}", e.what(), t), e.row());
    }
    dydt = Eigen::Map<const Eigen::VectorXd>(u_.data(), 3 * n);
  };
  auto on_accept = [&](double t, double dt, Eigen::VectorXd& state) {
    Eigen::Map<Points> xs(state.data(), n, 3);
    x_ = xs;
    rescale_to_volume(topology, x_, volume0);
    xs = x_;
    t_ = t;
    dt_next_ = integrator_->proposed_step();
    counters_.rejected_steps = rejected_before + integrator_->stats().rejected;
    if (!on_step) return true;
    AcceptedStep s;
    s.time = t;
    s.dt = dt;
    s.positions = &x_;
    return on_step(s);
  };
  if (!integrator_resume_.is_null()) {
    integrator_->restore_checkpoint_state(integrator_resume_, integrator_resume_source_);
    integrator_resume_ = nullptr;
  } else if (integrator_continues_) {
    integrator_->restore_checkpoint_state(integrator_->checkpoint_state(), "BIM");
  }
  integrator_continues_ = true;
  const IntegratorStats st = integrator_->integrate(rhs, t_, t_end, y, dt_next_, on_accept);
  counters_.rejected_steps = rejected_before + st.rejected;
  if (!st.stopped) dt_next_ = st.dt_next;
  return !st.stopped;
}

SolverState BimCapsuleSolver::save_state(const std::filesystem::path&, const std::string&) const {
  SolverState s;
  s.fields = {{"dt_next", dt_next_}};
  nlohmann::json state = integrator_->checkpoint_state();
  if (!state.empty()) s.fields["integrator"] = {{"name", integrator_->name()}, {"state", std::move(state)}};
  return s;
}

void BimCapsuleSolver::check_resumed_steps(double largest_step, const std::string& source) const {
  if (largest_step <= 0) {
    if (dt_next_ != 0)
      throw Error(fmt::format("{}: \"solver_state\": \"dt_next\" is {} but the run has taken no step (expected 0)",
                              source, dt_next_));
    return;
  }
  // 1e-5: the time series keeps a step to 6 digits.
  const double largest = integrator_->max_step_growth() * largest_step * (1 + 1e-5);
  if (!(dt_next_ > 0) || dt_next_ > largest)
    throw Error(fmt::format("{}: \"solver_state\": \"dt_next\" is {}, expected a step in (0, {:.6g}] ({} times the "
                            "largest step of the time series, {:.6g})",
                            source, dt_next_, largest, integrator_->max_step_growth(), largest_step));
}

nlohmann::json BimCapsuleSolver::summary() const {
  nlohmann::json j = {{"integrator", integrator_->name()}};
  nlohmann::json stats = integrator_->summary();
  if (!stats.empty()) j["integrator_stats"] = std::move(stats);
  return j;
}

void BimCapsuleSolver::restore_state(const Points& positions, double time, const SolverCounters& counters,
                                     const nlohmann::json& fields, const std::filesystem::path&,
                                     const std::string& source) {
  if (!fields.is_object() || !fields.contains("dt_next") || !fields.at("dt_next").is_number() ||
      !std::isfinite(fields.at("dt_next").get<double>()) || fields.at("dt_next").get<double>() < 0)
    throw Error(fmt::format("{}: \"solver_state\": \"dt_next\" must be a finite number >= 0", source));
  if (fields.contains("integrator")) {
    const nlohmann::json& in = fields.at("integrator");
    if (!in.is_object() || !in.contains("name") || !in.at("name").is_string() || !in.contains("state"))
      throw Error(fmt::format("{}: \"solver_state\": \"integrator\" must be an object with \"name\" and \"state\"", source));
    if (in.at("name").get<std::string>() != integrator_->name())
      throw Error(fmt::format("{}: the checkpoint was written by integrator '{}', this run uses '{}'", source,
                              in.at("name").get<std::string>(), integrator_->name()));
  }
  restart(positions, time, fields.at("dt_next").get<double>());
  if (fields.contains("integrator")) {
    integrator_resume_ = fields.at("integrator").at("state");
    integrator_resume_source_ = source;
  }
  counters_ = counters;
}

}  // namespace bendlab
