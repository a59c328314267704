#pragma once
// The IbCapsuleSolver (flow/lbm/ib_capsule_solver.hpp) of LbmCapsuleSolver over the ranks of an MPI
// communicator: the fluid is a DistributedLattice (y-slabs), the membrane is whole on every rank. Same options,
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

#include "bendlab/flow/lbm/ib_capsule_solver.hpp"
#include "bendlab/parallel/distributed_lattice.hpp"

namespace bendlab::parallel {

class MpiLbmCapsuleSolver final : public IbCapsuleSolver {
 public:
  /// As LbmCapsuleSolver's constructor (the same errors), on the ranks of `comm` (collective).
  MpiLbmCapsuleSolver(std::shared_ptr<const MembraneModel> membrane, LbmSolverOptions options, MPI_Comm comm);

  const DistributedLattice& fluid() const { return fluid_; }

 private:
  std::int64_t fluid_step_count() const override { return fluid_.step_count(); }
  void ib_step(Points& X, const Points& F, Points& U) override;
  void check_fluid() const override;
  void write_fluid(const std::filesystem::path& file) const override;
  std::int64_t read_fluid(const std::filesystem::path& file, std::int64_t step) override;

  DistributedLattice fluid_;
  // Scratch of ib_step(): kernels, owner rank of each node's kernel (-1: straddles slabs), offsets
  // of its terms in the reduced buffer.
  std::vector<lbm::IbStencil> stencils_;
  std::vector<int> owner_;
  std::vector<Eigen::Index> offsets_;
  std::vector<double> terms_, sums_;
};

}  // namespace bendlab::parallel
