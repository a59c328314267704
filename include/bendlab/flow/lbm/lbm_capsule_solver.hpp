#pragma once
// The immersed-boundary lattice Boltzmann method for a capsule in linear shear flow (paper section
// 4.3.2; technical note shared/spec/LBM_IBM.md) on one serial lattice: the IbCapsuleSolver
// (ib_capsule_solver.hpp: units, reporting, blow-up checks, checkpoint state) whose fluid is a
// D3Q19 lbm::Lattice between two walls moving with -+v e_x (lattice.hpp), coupled to the nodes by
// lbm::ib_step (immersed_boundary.hpp).
#include <cstdint>
#include <memory>

#include "bendlab/flow/lbm/ib_capsule_solver.hpp"
#include "bendlab/flow/lbm/lattice.hpp"

namespace bendlab {

class LbmCapsuleSolver final : public IbCapsuleSolver {
 public:
  /// Starts from the membrane's reference shape with its volume centroid at the box centre, the
  /// fluid in the exact wall-driven shear flow (Lattice::initialise_shear_flow), at time 0.
  /// Throws bendlab::Error for a null membrane, a non-positive radius or sample_every, a lattice
  /// without walls or shear, or a reference shape whose kernel support reaches a wall.
  LbmCapsuleSolver(std::shared_ptr<const MembraneModel> membrane, LbmSolverOptions options);

  const lbm::Lattice& lattice() const { return lattice_; }

 private:
  std::int64_t fluid_step_count() const override { return lattice_.step_count(); }
  void ib_step(Points& X, const Points& F, Points& U) override;
  void check_fluid() const override;
  void write_fluid(const std::filesystem::path& file) const override;
  std::int64_t read_fluid(const std::filesystem::path& file, std::int64_t step) override;

  lbm::Lattice lattice_;
};

}  // namespace bendlab
