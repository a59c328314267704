#include "bendlab/parallel/mpi_suspension_solver.hpp"

#include <fmt/format.h>

#include "bendlab/parallel/distributed_checkpoint.hpp"

namespace bendlab::parallel {

MpiSuspensionSolver::MpiSuspensionSolver(SuspensionSolverOptions options, MPI_Comm comm)
    : SuspensionSolver(options), suspension_(options.suspension, comm) {}

void MpiSuspensionSolver::set_fluid(lbm::Lattice whole) {
  // This rank's layers of the whole lattice's raw store (slot-major, x fastest), as
  // DistributedLattice::restore_owned takes them.
  DistributedLattice& fluid = suspension_.fluid();
  const lbm::LatticeConfig& g = fluid.config();
  if (whole.nx() != g.nx || whole.ny() != g.ny || whole.nz() != g.nz) throw Error("suspension: the fluid set has another size");
  const SlabDecomposition& s = fluid.slab();
  const std::vector<double> raw = whole.raw_populations();
  const std::size_t n = whole.num_nodes(), layer = static_cast<std::size_t>(g.nx) * s.count;
  std::vector<double> owned;
  owned.reserve(lbm::kQ * layer * g.nz);
  for (int q = 0; q < lbm::kQ; ++q)
    for (int k = 0; k < g.nz; ++k) {
      const auto* from = raw.data() + q * n + static_cast<std::size_t>(g.nx) * (s.begin + static_cast<std::size_t>(g.ny) * k);
      owned.insert(owned.end(), from, from + layer);
    }
  fluid.restore_owned(owned, whole.step_count());
}

std::vector<double> MpiSuspensionSolver::line_velocity_sums() const {
  // Each rank's own lines as lbm::line_velocity_sums adds them; zeros elsewhere, so the sum over
  // the ranks is exact.
  const DistributedLattice& fluid = suspension_.fluid();
  const lbm::LatticeConfig& g = fluid.config();
  const SlabDecomposition& s = fluid.slab();
  const lbm::Lattice& local = fluid.local();
  std::vector<double> lines(static_cast<std::size_t>(g.ny) * g.nz, 0.0), sums(lines.size());
  for (int k = 0; k < g.nz; ++k)
    for (int j = s.begin; j < s.begin + s.count; ++j) {
      if (local.solid_row(j - s.begin + 1, k)) continue;
      double line = 0;
      for (int i = 0; i < g.nx; ++i) line += local.velocity(fluid.local_node(i, j, k)).x();
      lines[static_cast<std::size_t>(j) + static_cast<std::size_t>(g.ny) * k] = line;
    }
  MPI_Allreduce(lines.data(), sums.data(), static_cast<int>(lines.size()), MPI_DOUBLE, MPI_SUM, fluid.comm());
  return sums;
}

bool MpiSuspensionSolver::solid_line(int j, int k) const {
  // lbm::Lattice's rule: a row is solid where the section's wall holds its node's centre.
  const lbm::LatticeConfig& g = suspension_.fluid().config();
  if (!g.section) return false;
  const Vec3 x = suspension_.fluid().position(0, j, k);
  return g.section->solid(x.y(), x.z());
}

void MpiSuspensionSolver::layer_fields(int j, std::vector<Vec3>& velocity, std::vector<double>& density) const {
  const DistributedLattice& fluid = suspension_.fluid();
  const lbm::LatticeConfig& g = fluid.config();
  const std::size_t nodes = static_cast<std::size_t>(g.nx) * g.nz;
  std::vector<double> values(4 * nodes);
  if (fluid.slab().owns(j)) {
    for (int k = 0; k < g.nz; ++k)
      for (int i = 0; i < g.nx; ++i) {
        const std::size_t node = fluid.local_node(i, j, k), at = 4 * (i + static_cast<std::size_t>(g.nx) * k);
        const Vec3 u = fluid.local().velocity(node);
        values[at] = u.x(), values[at + 1] = u.y(), values[at + 2] = u.z(), values[at + 3] = fluid.local().density(node);
      }
  }
  MPI_Bcast(values.data(), static_cast<int>(values.size()), MPI_DOUBLE, fluid.slab().owner(j), fluid.comm());
  velocity.resize(nodes);
  density.resize(nodes);
  for (std::size_t n = 0; n < nodes; ++n) {
    velocity[n] = Vec3(values[4 * n], values[4 * n + 1], values[4 * n + 2]);
    density[n] = values[4 * n + 3];
  }
}

double MpiSuspensionSolver::wall_shear_stress() const {
  throw Error("the shear box's wall stress is not computed over MPI ranks: run --geometry shear on one process");
}

void MpiSuspensionSolver::write_fluid(const std::filesystem::path& file) const { write_checkpoint(suspension_.fluid(), file); }

std::int64_t MpiSuspensionSolver::read_state(const std::filesystem::path& file, std::int64_t step, const Points& X) {
  DistributedLattice restored(suspension_.fluid().config(), suspension_.fluid().comm());
  read_checkpoint(restored, file);
  const std::int64_t file_step = restored.step_count();
  if (file_step == step) {
    suspension_.fluid() = std::move(restored);
    suspension_.restore(X);
  }
  return file_step;
}

}  // namespace bendlab::parallel
