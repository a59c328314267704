#include "bendlab/flow/lbm/ib_capsule_solver.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "bendlab/flow/lbm/fluid_state.hpp"
#include "bendlab/geometry/measures.hpp"

namespace bendlab {

namespace {

const std::shared_ptr<const MembraneModel>& checked(const std::shared_ptr<const MembraneModel>& m,
                                                    const LbmSolverOptions& o) {
  if (m == nullptr) throw Error("LBM: no membrane model");
  if (!(o.radius > 0) || !std::isfinite(o.radius)) throw Error(fmt::format("LBM: radius {} must be positive", o.radius));
  if (!(o.sample_every > 0) || !std::isfinite(o.sample_every))
    throw Error(fmt::format("LBM: sample_every {} must be positive", o.sample_every));
  if (!o.offset.allFinite() || o.offset.cwiseAbs().maxCoeff() > 1.0)
    throw Error(fmt::format("LBM: offset ({}, {}, {}) must be within [-1, 1] dx in each component", o.offset[0],
                            o.offset[1], o.offset[2]));
  if (!(o.lattice.shear_rate > 0) || !std::isfinite(o.lattice.shear_rate))
    throw Error("LBM: the lattice parameters have no shear rate (use lbm::capsule_run_parameters)");
  return m;
}

}  // namespace

IbCapsuleSolver::IbCapsuleSolver(std::shared_ptr<const MembraneModel> membrane, LbmSolverOptions options)
    : membrane_(checked(membrane, options)), options_(std::move(options)) {}

void IbCapsuleSolver::place_capsule(double shear_rate, double viscosity) {
  gamma_ = shear_rate;
  force_scale_ = viscosity * gamma_ * options_.radius * options_.radius;
  sample_steps_ = std::max<std::int64_t>(1, std::llround(options_.sample_every / gamma_));
  x_ = membrane_->initial_positions();
  x_.rowwise() -= volume_centroid(membrane_->topology(), x_).transpose();
  X_ = options_.radius * x_;
  X_.rowwise() += options_.offset.transpose();
  x_ = X_ / options_.radius;  // the run's positions are the lattice ones over R (as after every step)
  const lbm::LatticeConfig g = options_.lattice.lattice_config();
  for (Eigen::Index k = 0; k < X_.rows(); ++k) lbm::ib_stencil({g.nx, g.ny, g.nz}, g.walls, row(X_, k), options_.kernel);
}

void IbCapsuleSolver::step() {
  const std::int64_t n = fluid_step_count() + 1;  // the step being taken
  try {
    membrane_->forces(x_, F_);
    F_ *= force_scale_;
    ib_step(X_, F_, U_);
  } catch (const Error& e) {
    throw Error(fmt::format("LBM step {}: {}", n, e.what()));
  }
  ++counters_.velocity_evaluations;
  const int nz = options_.lattice.lattice_config().nz;
  const double reach = 0.5 * nz - lbm::ib_kernel_half_width(options_.kernel);
  for (Eigen::Index k = 0; k < X_.rows(); ++k) {
    if (!std::isfinite(X_(k, 0)) || !std::isfinite(X_(k, 1)) || !std::isfinite(X_(k, 2)))
      throw Error(fmt::format("LBM blew up at step {}: membrane node {} has a non-finite position", n, k));
    if (std::abs(X_(k, 2)) > reach)
      throw Error(fmt::format("LBM step {}: membrane node {} at z = {:.4g} dx is within the kernel's reach of a wall "
                              "(walls at z = +-{})",
                              n, k, X_(k, 2), 0.5 * nz));
  }
  x_ = X_ / options_.radius;
  if (n - last_fluid_check_ >= kFluidCheckSteps) {
    check_fluid();
    last_fluid_check_ = n;
  }
}

bool IbCapsuleSolver::advance(double t_end, const OnStep& on_step) {
  std::int64_t last_report = fluid_step_count();
  while (time() < t_end) {
    step();
    const std::int64_t n = fluid_step_count();
    if (n % sample_steps_ != 0 && time() < t_end) continue;
    if (!on_step) {
      last_report = n;
      continue;
    }
    AcceptedStep s;
    s.time = time();
    s.dt = static_cast<double>(n - last_report) * gamma_;
    s.positions = &x_;
    last_report = n;
    if (!on_step(s)) return false;
  }
  return true;
}

bool IbCapsuleSolver::is_side_file(const std::string& name) const { return lbm::is_fluid_file(name); }

SolverState IbCapsuleSolver::save_state(const std::filesystem::path& folder, const std::string& tag) const {
  check_fluid();  // never checkpoint a broken fluid
  SolverState s;
  const std::string fluid = lbm::fluid_file_name(tag);
  write_fluid(folder / fluid);
  s.side_files.push_back(fluid);
  s.fields = lbm::fluid_state_fields(fluid, fluid_step_count(), X_);
  return s;
}

void IbCapsuleSolver::restore_state(const Points& positions, double time, const SolverCounters& counters,
                                    const nlohmann::json& fields, const std::filesystem::path& folder,
                                    const std::string& source) {
  auto bad = [&](const std::string& what) { return Error(fmt::format("{}: \"solver_state\": {}", source, what)); };
  const lbm::FluidStateFields saved = lbm::parse_fluid_state(fields, X_.rows(), source);
  const std::int64_t n = saved.lattice_step;
  const Points& X = saved.X;
  const double t = static_cast<double>(n) * gamma_;
  if (std::abs(t - time) > 1e-9 * std::max(1.0, std::abs(time)))
    throw bad(fmt::format("\"lattice_step\" {} is gamma t = {}, the checkpoint's time is {}", n, t, time));
  if (positions.rows() != X.rows() || ((X / options_.radius) - positions).cwiseAbs().maxCoeff() > 1e-9)
    throw bad("\"positions_lattice\" do not match the checkpoint's positions");
  std::int64_t file_step = 0;
  try {
    file_step = read_fluid(folder / saved.fluid, n);
  } catch (const Error& e) {
    throw Error(fmt::format("{}: {}", source, e.what()));
  }
  if (file_step != n) throw bad(fmt::format("the fluid file is at step {}, \"lattice_step\" is {}", file_step, n));
  X_ = X;
  x_ = X_ / options_.radius;
  counters_ = counters;
  last_fluid_check_ = n;
}

}  // namespace bendlab
