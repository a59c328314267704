#pragma once
// LbmCapsuleSolver (flow/lbm/lbm_capsule_solver.hpp) over the ranks of an MPI communicator: the
// fluid is a DistributedLattice (y-slabs), the membrane is whole on every rank. Same options,
// same steps, same reports, same checkpoints (name "lbm", the same solver_state fields and fluid
// file), so a run may be resumed with another rank count or by the serial solver.
//
// The membrane across ranks (docs/mpi.md): every rank holds all membrane nodes and computes their
// forces itself (the same positions give the same forces on every rank: no communication; the
// force evaluation is repeated on every rank, small next to the fluid for the paper's meshes, but
// it does not shrink with the rank count). Each rank spreads every node's force onto its own
// layers only (the serial order of the sums per lattice node: the serial force field) and
// interpolates from its own layers only: a node whose kernel lies in one slab is summed by the
// owner in the serial order; for a node whose kernel straddles slabs every rank contributes its
// terms w u separately. The buffer (3 doubles per node, 3 per kernel node for straddling ones) is
// summed on rank 0 (MPI_Reduce: each entry has one non-zero contribution, so the sums are exact)
// and broadcast; every rank then adds the straddling nodes' terms in the serial order. So the
// node velocities, positions and the fluid are the serial solver's bit for bit, on every rank.
// Communication per step: the halo (slab_decomposition.hpp) plus 2 x (3 N + 3 x 8 x straddling
// nodes) doubles for the phi2 kernel.
//
// Every member that steps, saves, restores or checks the fluid is collective; an error (blow-up,
// a node reaching a wall, a failed file) is thrown on every rank alike.
#include <mpi.h>

#include <cstdint>
#include <memory>
#include <vector>

#include "bendlab/capsule/capsule_solver.hpp"
#include "bendlab/flow/lbm/lbm_capsule_solver.hpp"
#include "bendlab/parallel/distributed_lattice.hpp"

namespace bendlab::parallel {

class MpiLbmCapsuleSolver final : public CapsuleSolver {
 public:
  static constexpr std::int64_t kFluidCheckSteps = LbmCapsuleSolver::kFluidCheckSteps;

  /// As LbmCapsuleSolver's constructor (the same errors), on the ranks of `comm` (collective).
  MpiLbmCapsuleSolver(std::shared_ptr<const MembraneModel> membrane, LbmSolverOptions options, MPI_Comm comm);

  std::string name() const override { return "lbm"; }
  const MembraneModel& membrane() const override { return *membrane_; }
  const Points& positions() const override { return x_; }
  double time() const override { return static_cast<double>(fluid_.step_count()) * gamma_; }
  bool advance(double t_end, const OnStep& on_step) override;
  SolverCounters counters() const override { return counters_; }
  SolverState save_state(const std::filesystem::path& folder, const std::string& tag) const override;
  void restore_state(const Points& positions, double time, const SolverCounters& counters,
                     const nlohmann::json& fields, const std::filesystem::path& folder,
                     const std::string& source) override;

  void step();

  const DistributedLattice& fluid() const { return fluid_; }
  const Points& lattice_positions() const { return X_; }
  std::int64_t sample_steps() const { return sample_steps_; }

 private:
  void check_fluid() const;

  std::shared_ptr<const MembraneModel> membrane_;
  LbmSolverOptions options_;
  DistributedLattice fluid_;
  double gamma_ = 0, force_scale_ = 0;
  std::int64_t sample_steps_ = 1;
  Points X_, x_, F_, U_;
  // Scratch of step(): kernels, owner rank of each node's kernel (-1: straddles slabs), offsets of
  // its terms in the reduced buffer.
  std::vector<lbm::IbStencil> stencils_;
  std::vector<int> owner_;
  std::vector<Eigen::Index> offsets_;
  std::vector<double> terms_, sums_;
  SolverCounters counters_;
  std::int64_t last_fluid_check_ = 0;
};

}  // namespace bendlab::parallel
