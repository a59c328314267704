#include "bendlab/flow/lbm/ib_capsule_solver.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <regex>

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

bool IbCapsuleSolver::is_side_file(const std::string& name) const {
  static const std::regex fluid_re(R"(lbm_fluid_\d{5,}\.bin)");
  return std::regex_match(name, fluid_re);
}

SolverState IbCapsuleSolver::save_state(const std::filesystem::path& folder, const std::string& tag) const {
  check_fluid();  // never checkpoint a broken fluid
  SolverState s;
  const std::string fluid = fmt::format("lbm_fluid_{}.bin", tag);
  write_fluid(folder / fluid);
  s.side_files.push_back(fluid);
  s.fields = {{"fluid", fluid},
              {"lattice_step", fluid_step_count()},
              {"positions_lattice", std::vector<double>(X_.data(), X_.data() + X_.size())}};
  return s;
}

void IbCapsuleSolver::restore_state(const Points& positions, double time, const SolverCounters& counters,
                                    const nlohmann::json& fields, const std::filesystem::path& folder,
                                    const std::string& source) {
  auto bad = [&](const std::string& what) { return Error(fmt::format("{}: \"solver_state\": {}", source, what)); };
  if (!fields.is_object()) throw bad("must be an object");
  if (!fields.contains("fluid") || !fields.at("fluid").is_string()) throw bad("\"fluid\" must name the fluid file");
  if (!is_side_file(fields.at("fluid").get<std::string>()))
    throw bad(fmt::format("\"fluid\" is {}, expected lbm_fluid_NNNNN.bin", fields.at("fluid").dump()));
  if (!fields.contains("lattice_step") || !fields.at("lattice_step").is_number_integer() ||
      fields.at("lattice_step").get<std::int64_t>() < 0)
    throw bad("\"lattice_step\" must be an integer >= 0");
  const std::int64_t n = fields.at("lattice_step").get<std::int64_t>();
  if (!fields.contains("positions_lattice") || !fields.at("positions_lattice").is_array() ||
      fields.at("positions_lattice").size() != static_cast<std::size_t>(X_.size()))
    throw bad(fmt::format("\"positions_lattice\" must hold {} numbers", X_.size()));
  Points X(X_.rows(), 3);
  for (Eigen::Index i = 0; i < X.size(); ++i) {
    const auto& v = fields.at("positions_lattice")[static_cast<std::size_t>(i)];
    if (!v.is_number() || !std::isfinite(v.get<double>())) throw bad("\"positions_lattice\" has a non-finite entry");
    X.data()[i] = v.get<double>();
  }
  const double t = static_cast<double>(n) * gamma_;
  if (std::abs(t - time) > 1e-9 * std::max(1.0, std::abs(time)))
    throw bad(fmt::format("\"lattice_step\" {} is gamma t = {}, the checkpoint's time is {}", n, t, time));
  if (positions.rows() != X.rows() || ((X / options_.radius) - positions).cwiseAbs().maxCoeff() > 1e-9)
    throw bad("\"positions_lattice\" do not match the checkpoint's positions");
  std::int64_t file_step = 0;
  try {
    file_step = read_fluid(folder / fields.at("fluid").get<std::string>(), n);
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
