#pragma once
// The suspension solver (flow/suspension_solver.hpp) over the ranks of an MPI communicator: the
// cells and the fluid of parallel::MpiSuspension (each cell owned whole by one rank, the fluid in
// y-slabs). The same options, reports, checkpoints and figures as LbmSuspensionSolver, bit for bit,
// so a run may be resumed with another rank count or by the serial solver (docs/mpi.md, "Many
// cells").
//
// What crosses ranks besides the suspension's own step: at each report, every cell's positions and
// vertex velocities gathered onto every rank (the run loop and the recorder read them on each);
// the line sums of u_x (each rank its own layers' lines, summed over the ranks: every entry has
// one non-zero term, so the sum is exact) and, at a snapshot, the fluid slice from the rank that
// owns its layer; the checkpoint through MPI-IO (distributed_checkpoint.hpp). The cell-free flow is
// relaxed on one whole lattice on every rank, and set_fluid keeps each rank's layers of it.
//
// The shear box's wall stress is not distributed: wall_shear_stress throws (flow under mpirun
// takes a tube or a channel).
#include <mpi.h>

#include "bendlab/flow/suspension_solver.hpp"
#include "bendlab/parallel/mpi_suspension.hpp"

namespace bendlab::parallel {

class MpiSuspensionSolver final : public SuspensionSolver {
 public:
  /// As LbmSuspensionSolver's constructor (the same errors), on the ranks of `comm`.
  MpiSuspensionSolver(SuspensionSolverOptions options, MPI_Comm comm);

  void set_fluid(lbm::Lattice whole) override;
  std::vector<double> line_velocity_sums() const override;
  bool solid_line(int j, int k) const override;
  Vec3 node_position(int i, int j, int k) const override { return suspension_.fluid().position(i, j, k); }
  void layer_fields(int j, std::vector<Vec3>& velocity, std::vector<double>& density) const override;
  double wall_shear_stress() const override;
  double shear_rate() const override { return suspension_.fluid().shear_rate(); }
  double viscosity() const override { return suspension_.fluid().viscosity(); }

  MpiSuspension& suspension() { return suspension_; }
  const MpiSuspension& suspension() const { return suspension_; }

 private:
  int num_cells() const override { return suspension_.num_cells(); }
  const MembraneModel& cell_membrane(int c) const override { return suspension_.membrane(c); }
  Eigen::Index cell_first_row(int c) const override { return suspension_.first_row(c); }
  int add_lattice_cell(std::shared_ptr<const MembraneModel> membrane, const Points& X) override {
    return suspension_.add_cell(std::move(membrane), X);
  }
  void step_suspension() override { suspension_.step(); }
  std::int64_t lattice_steps() const override { return suspension_.steps(); }
  Points lattice_positions() const override { return suspension_.gather_positions(); }
  Points lattice_velocities() const override { return suspension_.gather_velocities(); }
  void check_fluid() const override { suspension_.fluid().check_blow_up(); }
  void write_fluid(const std::filesystem::path& file) const override;
  std::int64_t read_state(const std::filesystem::path& file, std::int64_t step, const Points& X) override;

  MpiSuspension suspension_;
};

}  // namespace bendlab::parallel
