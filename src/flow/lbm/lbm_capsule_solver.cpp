#include "bendlab/flow/lbm/lbm_capsule_solver.hpp"

#include "bendlab/flow/lbm/checkpoint.hpp"
#include "bendlab/flow/lbm/diagnostics.hpp"

namespace bendlab {

LbmCapsuleSolver::LbmCapsuleSolver(std::shared_ptr<const MembraneModel> membrane, LbmSolverOptions options)
    : IbCapsuleSolver(std::move(membrane), std::move(options)), lattice_(this->options().lattice.lattice_config()) {
  place_capsule(lattice_.shear_rate(), lattice_.viscosity());
  lattice_.initialise_shear_flow();
}

void LbmCapsuleSolver::ib_step(Points& X, const Points& F, Points& U) {
  lbm::ib_step(lattice_, X, F, U, options().kernel);
}

void LbmCapsuleSolver::check_fluid() const {
  if (const auto b = lbm::find_blow_up(lattice_)) throw Error(b->message);
}

void LbmCapsuleSolver::write_fluid(const std::filesystem::path& file) const { lbm::write_checkpoint(lattice_, file); }

std::int64_t LbmCapsuleSolver::read_fluid(const std::filesystem::path& file, std::int64_t step) {
  lbm::Lattice restored(lattice_.config());
  lbm::read_checkpoint(restored, file);
  const std::int64_t file_step = restored.step_count();
  if (file_step == step) lattice_ = std::move(restored);
  return file_step;
}

}  // namespace bendlab
