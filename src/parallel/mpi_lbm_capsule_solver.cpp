#include "bendlab/parallel/mpi_lbm_capsule_solver.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "bendlab/geometry/measures.hpp"
#include "bendlab/parallel/distributed_checkpoint.hpp"

namespace bendlab::parallel {

namespace {

const std::shared_ptr<const MembraneModel>& checked(const std::shared_ptr<const MembraneModel>& m,
                                                    const LbmSolverOptions& o) {
  if (m == nullptr) throw Error("LBM: no membrane model");
  if (!(o.radius > 0) || !std::isfinite(o.radius)) throw Error(fmt::format("LBM: radius {} must be positive", o.radius));
  if (!(o.sample_every > 0) || !std::isfinite(o.sample_every))
    throw Error(fmt::format("LBM: sample_every {} must be positive", o.sample_every));
  if (!(o.lattice.shear_rate > 0) || !std::isfinite(o.lattice.shear_rate))
    throw Error("LBM: the lattice parameters have no shear rate (use lbm::capsule_run_parameters)");
  return m;
}

}  // namespace

MpiLbmCapsuleSolver::MpiLbmCapsuleSolver(std::shared_ptr<const MembraneModel> membrane, LbmSolverOptions options,
                                         MPI_Comm comm)
    : membrane_(checked(membrane, options)), options_(options), fluid_(options.lattice.lattice_config(), comm) {
  gamma_ = fluid_.shear_rate();
  force_scale_ = fluid_.viscosity() * gamma_ * options_.radius * options_.radius;
  sample_steps_ = std::max<std::int64_t>(1, std::llround(options_.sample_every / gamma_));
  x_ = membrane_->reference_positions();
  x_.rowwise() -= volume_centroid(membrane_->topology(), x_).transpose();
  X_ = options_.radius * x_;
  const lbm::LatticeConfig& g = fluid_.config();
  for (Eigen::Index k = 0; k < X_.rows(); ++k) lbm::ib_stencil({g.nx, g.ny, g.nz}, g.walls, row(X_, k), options_.kernel);
  fluid_.initialise_shear_flow();
}

void MpiLbmCapsuleSolver::check_fluid() const {
  // The first node in global index order with a non-finite or non-positive density, as
  // lbm::find_blow_up reports it.
  const lbm::LatticeConfig& g = fluid_.config();
  const SlabDecomposition& s = fluid_.slab();
  const lbm::Lattice& local = fluid_.local();
  long long first = std::numeric_limits<long long>::max();
  double rho_first = 0;
  for (int k = 0; k < g.nz && first == std::numeric_limits<long long>::max(); ++k)
    for (int j = s.begin; j < s.begin + s.count && first == std::numeric_limits<long long>::max(); ++j)
      for (int i = 0; i < g.nx; ++i) {
        const double rho = local.density(fluid_.local_node(i, j, k));
        if (!std::isfinite(rho) || !(rho > 0)) {
          first = i + static_cast<long long>(g.nx) * (j + static_cast<long long>(g.ny) * k);
          rho_first = rho;
          break;
        }
      }
  long long global_first = 0;
  MPI_Allreduce(&first, &global_first, 1, MPI_LONG_LONG, MPI_MIN, fluid_.comm());
  if (global_first == std::numeric_limits<long long>::max()) return;
  const int i = static_cast<int>(global_first % g.nx);
  const long long r = global_first / g.nx;
  const int j = static_cast<int>(r % g.ny), k = static_cast<int>(r / g.ny);
  MPI_Bcast(&rho_first, 1, MPI_DOUBLE, s.owner(j), fluid_.comm());
  const Vec3 x = fluid_.position(i, j, k);
  throw Error(fmt::format("LBM blew up at step {}: density {} at node ({}, {}, {}) (position {:.3g}, {:.3g}, {:.3g})",
                          fluid_.step_count(), rho_first, i, j, k, x.x(), x.y(), x.z()));
}

void MpiLbmCapsuleSolver::step() {
  const std::int64_t n = fluid_.step_count() + 1;
  try {
    membrane_->forces(x_, F_);
    F_ *= force_scale_;
    const lbm::LatticeConfig& g = fluid_.config();
    const SlabDecomposition& slab = fluid_.slab();
    const Eigen::Index N = X_.rows();
    // The kernel of every node (global indices) and which ranks own its non-zero weights: the
    // same on every rank, as the positions are.
    stencils_.resize(static_cast<std::size_t>(N));
    offsets_.resize(static_cast<std::size_t>(N) + 1);
    owner_.resize(static_cast<std::size_t>(N));
    offsets_[0] = 0;
    auto layer = [&](std::size_t node) { return static_cast<int>((node / g.nx) % g.ny); };
    auto local = [&](std::size_t node) {
      const std::size_t r = node / g.nx;
      return fluid_.local_node(static_cast<int>(node % g.nx), static_cast<int>(r % g.ny), static_cast<int>(r / g.ny));
    };
    for (Eigen::Index m = 0; m < N; ++m) {
      const lbm::IbStencil& st = stencils_[m] = lbm::ib_stencil({g.nx, g.ny, g.nz}, g.walls, row(X_, m), options_.kernel);
      int lo = slab.ranks, hi = -1;
      for (int s = 0; s < st.size; ++s) {
        if (st.weight[s] == 0.0) continue;
        const int r = slab.owner(layer(st.node[s]));
        lo = std::min(lo, r);
        hi = std::max(hi, r);
      }
      owner_[m] = lo == hi ? lo : -1;  // -1: the kernel straddles slabs
      offsets_[m + 1] = offsets_[m] + (owner_[m] >= 0 ? 3 : 3 * st.size);
    }
    // Spread onto the owned layers, node by node in the serial order: the serial force field.
    lbm::Lattice& lat = fluid_.local();
    lat.clear_force();
    for (Eigen::Index m = 0; m < N; ++m) {
      const lbm::IbStencil& st = stencils_[m];
      const Vec3 Fm = row(F_, m);
      for (int s = 0; s < st.size; ++s)
        if (st.weight[s] != 0.0 && slab.owns(layer(st.node[s]))) lat.add_force(local(st.node[s]), st.weight[s] * Fm);
    }
    fluid_.step();
    // Interpolate: a node within one slab is summed by its owner as in the serial solver; for a
    // node whose kernel straddles slabs each rank sends its terms, and every rank sums them in the
    // serial order. Sums over ranks add zeros only, so every node's velocity is the serial one bit
    // for bit.
    terms_.assign(static_cast<std::size_t>(offsets_[N]), 0.0);
    for (Eigen::Index m = 0; m < N; ++m) {
      const lbm::IbStencil& st = stencils_[m];
      double* t = terms_.data() + offsets_[m];
      if (owner_[m] >= 0) {
        if (owner_[m] != slab.rank) continue;
        Vec3 u = Vec3::Zero();
        for (int s = 0; s < st.size; ++s)
          if (st.weight[s] != 0.0) u += st.weight[s] * lat.velocity(local(st.node[s]));
        for (int d = 0; d < 3; ++d) t[d] = u[d];
      } else {
        for (int s = 0; s < st.size; ++s)
          if (st.weight[s] != 0.0 && slab.owns(layer(st.node[s]))) {
            const Vec3 term = st.weight[s] * lat.velocity(local(st.node[s]));
            for (int d = 0; d < 3; ++d) t[3 * s + d] = term[d];
          }
      }
    }
    sums_.resize(terms_.size());
    const int count = static_cast<int>(terms_.size());
    MPI_Reduce(terms_.data(), sums_.data(), count, MPI_DOUBLE, MPI_SUM, 0, fluid_.comm());
    MPI_Bcast(sums_.data(), count, MPI_DOUBLE, 0, fluid_.comm());
    U_.resize(N, 3);
    for (Eigen::Index m = 0; m < N; ++m) {
      const double* t = sums_.data() + offsets_[m];
      Vec3 u = Vec3::Zero();
      if (owner_[m] >= 0) {
        u = Vec3(t[0], t[1], t[2]);
      } else {
        const lbm::IbStencil& st = stencils_[m];
        for (int s = 0; s < st.size; ++s)
          if (st.weight[s] != 0.0) u += Vec3(t[3 * s], t[3 * s + 1], t[3 * s + 2]);
      }
      U_.row(m) = u.transpose();
    }
    lbm::euler_move(X_, U_, 1.0);
  } catch (const Error& e) {
    throw Error(fmt::format("LBM step {}: {}", n, e.what()));
  }
  ++counters_.velocity_evaluations;
  const double reach = 0.5 * fluid_.config().nz - lbm::ib_kernel_half_width(options_.kernel);
  for (Eigen::Index k = 0; k < X_.rows(); ++k) {
    if (!std::isfinite(X_(k, 0)) || !std::isfinite(X_(k, 1)) || !std::isfinite(X_(k, 2)))
      throw Error(fmt::format("LBM blew up at step {}: membrane node {} has a non-finite position", n, k));
    if (std::abs(X_(k, 2)) > reach)
      throw Error(fmt::format("LBM step {}: membrane node {} at z = {:.4g} dx is within the kernel's reach of a wall "
                              "(walls at z = +-{})",
                              n, k, X_(k, 2), 0.5 * fluid_.config().nz));
  }
  x_ = X_ / options_.radius;
  if (n - last_fluid_check_ >= kFluidCheckSteps) {
    check_fluid();
    last_fluid_check_ = n;
  }
}

bool MpiLbmCapsuleSolver::advance(double t_end, const OnStep& on_step) {
  std::int64_t last_report = fluid_.step_count();
  while (time() < t_end) {
    step();
    const std::int64_t n = fluid_.step_count();
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

SolverState MpiLbmCapsuleSolver::save_state(const std::filesystem::path& folder, const std::string& tag) const {
  check_fluid();  // never checkpoint a broken fluid
  SolverState s;
  const std::string fluid = fmt::format("lbm_fluid_{}.bin", tag);
  write_checkpoint(fluid_, folder / fluid);
  s.side_files.push_back(fluid);
  s.fields = {{"fluid", fluid},
              {"lattice_step", fluid_.step_count()},
              {"positions_lattice", std::vector<double>(X_.data(), X_.data() + X_.size())}};
  return s;
}

void MpiLbmCapsuleSolver::restore_state(const Points& positions, double time, const SolverCounters& counters,
                                        const nlohmann::json& fields, const std::filesystem::path& folder,
                                        const std::string& source) {
  auto bad = [&](const std::string& what) { return Error(fmt::format("{}: \"solver_state\": {}", source, what)); };
  if (!fields.is_object()) throw bad("must be an object");
  if (!fields.contains("fluid") || !fields.at("fluid").is_string()) throw bad("\"fluid\" must name the fluid file");
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
  DistributedLattice restored(fluid_.config(), fluid_.comm());
  try {
    read_checkpoint(restored, folder / fields.at("fluid").get<std::string>());
  } catch (const Error& e) {
    throw Error(fmt::format("{}: {}", source, e.what()));
  }
  if (restored.step_count() != n)
    throw bad(fmt::format("the fluid file is at step {}, \"lattice_step\" is {}", restored.step_count(), n));
  fluid_ = std::move(restored);
  X_ = X;
  x_ = X_ / options_.radius;
  counters_ = counters;
  last_fluid_check_ = n;
}

}  // namespace bendlab::parallel
