#include "bendlab/parallel/mpi_lbm_capsule_solver.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "bendlab/geometry/measures.hpp"
#include "bendlab/parallel/distributed_checkpoint.hpp"

namespace bendlab::parallel {

MpiLbmCapsuleSolver::MpiLbmCapsuleSolver(std::shared_ptr<const MembraneModel> membrane, LbmSolverOptions options,
                                         MPI_Comm comm)
    : IbCapsuleSolver(std::move(membrane), std::move(options)), fluid_(this->options().lattice.lattice_config(), comm) {
  place_capsule(fluid_.shear_rate(), fluid_.viscosity());
  fluid_.initialise_shear_flow();
}

void MpiLbmCapsuleSolver::check_fluid() const { fluid_.check_blow_up(); }

void MpiLbmCapsuleSolver::ib_step(Points& X, const Points& F, Points& U) {
  const lbm::LatticeConfig& g = fluid_.config();
  const SlabDecomposition& slab = fluid_.slab();
  const Eigen::Index N = X.rows();
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
    const lbm::IbStencil& st = stencils_[m] = lbm::ib_stencil({g.nx, g.ny, g.nz}, g.walls, row(X, m), options().kernel);
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
    const Vec3 Fm = row(F, m);
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
  U.resize(N, 3);
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
    U.row(m) = u.transpose();
  }
  lbm::euler_move(X, U, 1.0);
}

void MpiLbmCapsuleSolver::write_fluid(const std::filesystem::path& file) const { write_checkpoint(fluid_, file); }

std::int64_t MpiLbmCapsuleSolver::read_fluid(const std::filesystem::path& file, std::int64_t step) {
  DistributedLattice restored(fluid_.config(), fluid_.comm());
  read_checkpoint(restored, file);
  const std::int64_t file_step = restored.step_count();
  if (file_step == step) fluid_ = std::move(restored);
  return file_step;
}

}  // namespace bendlab::parallel
