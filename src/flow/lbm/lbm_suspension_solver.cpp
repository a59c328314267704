#include "bendlab/flow/lbm/lbm_suspension_solver.hpp"

#include "bendlab/flow/lbm/checkpoint.hpp"
#include "bendlab/flow/lbm/diagnostics.hpp"
#include "bendlab/flow/lbm/wall_stress.hpp"

namespace bendlab {

LbmSuspensionSolver::LbmSuspensionSolver(SuspensionSolverOptions options)
    : SuspensionSolver(options), suspension_(options.suspension) {}

void LbmSuspensionSolver::set_fluid(lbm::Lattice whole) { suspension_.restore(std::move(whole), suspension_.positions()); }

std::vector<double> LbmSuspensionSolver::line_velocity_sums() const { return lbm::line_velocity_sums(suspension_.lattice()); }

void LbmSuspensionSolver::layer_fields(int j, std::vector<Vec3>& velocity, std::vector<double>& density) const {
  const lbm::Lattice& lattice = suspension_.lattice();
  velocity.clear();
  density.clear();
  for (int k = 0; k < lattice.nz(); ++k)
    for (int i = 0; i < lattice.nx(); ++i) {
      velocity.push_back(lattice.velocity(lattice.index(i, j, k)));
      density.push_back(lattice.density(lattice.index(i, j, k)));
    }
}

double LbmSuspensionSolver::wall_shear_stress() const { return lbm::wall_shear_stress(suspension_.lattice()); }

void LbmSuspensionSolver::check_fluid() const {
  if (const auto b = lbm::find_blow_up(suspension_.lattice())) throw Error(b->message);
}

void LbmSuspensionSolver::write_fluid(const std::filesystem::path& file) const {
  lbm::write_checkpoint(suspension_.lattice(), file);
}

std::int64_t LbmSuspensionSolver::read_state(const std::filesystem::path& file, std::int64_t step, const Points& X) {
  lbm::Lattice restored(suspension_.lattice().config());
  lbm::read_checkpoint(restored, file);
  const std::int64_t file_step = restored.step_count();
  if (file_step == step) suspension_.restore(std::move(restored), X);
  return file_step;
}

}  // namespace bendlab
