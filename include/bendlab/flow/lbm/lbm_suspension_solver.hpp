#pragma once
// Many cells in a lattice Boltzmann fluid (lbm_suspension.hpp) on one process, behind the run's
// solver interface (flow/suspension_solver.hpp: the units, reports, blow-up checks and checkpoint
// state are the base's).
#include <filesystem>
#include <memory>

#include "bendlab/flow/lbm/lbm_suspension.hpp"
#include "bendlab/flow/suspension_solver.hpp"

namespace bendlab {

class LbmSuspensionSolver final : public SuspensionSolver {
 public:
  /// An empty suspension at rest at time 0; add cells and set the fluid before the run starts.
  /// Throws bendlab::Error for non-positive or non-finite units or sample_every, and as
  /// LbmSuspension does.
  explicit LbmSuspensionSolver(SuspensionSolverOptions options);

  void set_fluid(lbm::Lattice whole) override;
  std::vector<double> line_velocity_sums() const override;
  bool solid_line(int j, int k) const override { return suspension_.lattice().solid_row(j, k); }
  Vec3 node_position(int i, int j, int k) const override { return suspension_.lattice().position(i, j, k); }
  void layer_fields(int j, std::vector<Vec3>& velocity, std::vector<double>& density) const override;
  double wall_shear_stress() const override;
  double shear_rate() const override { return suspension_.lattice().shear_rate(); }
  double viscosity() const override { return suspension_.lattice().viscosity(); }

  /// The suspension, for its fluid and cells (a caller that changes it before the run starts calls
  /// sync_positions afterwards).
  lbm::LbmSuspension& suspension() { return suspension_; }
  const lbm::LbmSuspension& suspension() const { return suspension_; }

 private:
  int num_cells() const override { return suspension_.num_cells(); }
  const MembraneModel& cell_membrane(int c) const override { return suspension_.membrane(c); }
  Eigen::Index cell_first_row(int c) const override { return suspension_.first_row(c); }
  int add_lattice_cell(std::shared_ptr<const MembraneModel> membrane, const Points& X) override {
    return suspension_.add_cell(std::move(membrane), X);
  }
  void step_suspension() override { suspension_.step(); }
  std::int64_t lattice_steps() const override { return suspension_.steps(); }
  Points lattice_positions() const override { return suspension_.positions(); }
  Points lattice_velocities() const override { return suspension_.velocities(); }
  void check_fluid() const override;
  void write_fluid(const std::filesystem::path& file) const override;
  std::int64_t read_state(const std::filesystem::path& file, std::int64_t step, const Points& X) override;

  lbm::LbmSuspension suspension_;
};

}  // namespace bendlab
