#pragma once
// Many cells in a lattice Boltzmann fluid behind the solver interface of a run
// (capsule/capsule_solver.hpp): each cell is a body, and the run loop (capsule_run.hpp) keeps the
// folder, the snapshots of all cells, the checkpoint and resume, as for one capsule. This base
// holds what does not depend on where the fluid and the cells live: the units, the report schedule,
// the blow-up checks, the checkpoint state; two solvers provide the suspension:
//  - LbmSuspensionSolver (lbm/lbm_suspension_solver.hpp): one process (lbm::LbmSuspension);
//  - parallel::MpiSuspensionSolver (parallel/mpi_suspension_solver.hpp): the fluid in y-slabs over
//    MPI ranks, each cell owned by one rank (parallel::MpiSuspension). Its members that read the
//    fluid or gather the cells are collective (every rank calls them in the same order, as the
//    run loop and the suspension recorder do), and every figure equals the serial solver's bit for
//    bit.
//
// Units. The suspension steps in lattice units; the run sees physical ones: positions() in um
// (X dx), time() in seconds (lattice steps dt). The step is reported to the run every
// sample_every seconds (rounded to whole lattice steps, at least 1) and at the step that reaches
// t_end; AcceptedStep::dt is the time since the report before.
//
// Blow-up. Vertex positions are checked every step (by the suspension) and the fluid's density
// every kFluidCheckSteps steps and before every checkpoint: a non-finite or non-positive density
// throws bendlab::Error naming the lattice node and step, before the step is reported, so the
// run's last checkpoint stays the last good state.
//
// Checkpoint state: flow/lbm/fluid_state.hpp (the fluid file, the lattice step and every vertex
// in dx), so a resumed run repeats the uninterrupted one bit for bit, with either solver.
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "bendlab/capsule/capsule_solver.hpp"
#include "bendlab/flow/lbm/lattice.hpp"
#include "bendlab/flow/lbm/lbm_suspension.hpp"

namespace bendlab {

struct SuspensionSolverOptions {
  lbm::SuspensionOptions suspension;
  double dx_um = 0;         ///< um per lattice spacing
  double dt_seconds = 0;    ///< seconds per lattice step
  double sample_every = 0;  ///< seconds between reported steps (>= one lattice step)
};

class SuspensionSolver : public CapsuleSolver {
 public:
  static constexpr std::int64_t kFluidCheckSteps = 1000;

  std::string name() const final { return "lbm-suspension"; }
  /// The first cell's membrane (throws without cells).
  const MembraneModel& membrane() const final;
  /// bending_fallbacks: the vertex evaluations of the cells' bending methods that fell back to a
  /// simpler rule (BendingMethod::fallback_count, over the methods the cells share, in this process
  /// since they were made: a resumed run counts from its resume).
  nlohmann::json summary() const override;
  std::vector<SolverBody> bodies() const final;
  /// Every vertex, cell after cell, in um, as of the last report (or the last add_cell/restore).
  const Points& positions() const final { return x_; }
  double time() const final { return static_cast<double>(lattice_steps()) * options_.dt_seconds; }
  bool advance(double t_end, const OnStep& on_step) final;
  SolverCounters counters() const final { return counters_; }
  SolverState save_state(const std::filesystem::path& folder, const std::string& tag) const final;
  void restore_state(const Points& positions, double time, const SolverCounters& counters,
                     const nlohmann::json& fields, const std::filesystem::path& folder,
                     const std::string& source) final;
  bool is_side_file(const std::string& name) const final;

  const SuspensionSolverOptions& options() const { return options_; }
  /// Lattice steps between reports: sample_every in steps, rounded up to a multiple of
  /// suspension.membrane_every.
  std::int64_t sample_steps() const { return sample_steps_; }

  /// Adds a cell at positions X in um (lattice units inside; every process adds the same cells in
  /// the same order); returns its index.
  int add_cell(std::shared_ptr<const MembraneModel> lattice_membrane, const Points& X_um);
  /// Replaces the fluid by `whole`, a lattice of the options' configuration (the cell-free flow
  /// relaxed on one process), before the run starts.
  virtual void set_fluid(lbm::Lattice whole) = 0;
  /// positions() and vertex_velocities() from the suspension's (collective).
  void sync_positions();
  /// The vertex velocities of the last report (lattice units), every cell's.
  const Points& vertex_velocities() const { return u_; }

  /// Collective. Per line of nodes along x, index j + ny k: the sum of u_x over i = 0 .. nx - 1 in
  /// that order (lattice units; 0 for a solid row), as lbm::line_velocity_sums.
  virtual std::vector<double> line_velocity_sums() const = 0;
  /// Whether the row (j, k) lies in the vessel's wall, and the position of node (i, j, k)
  /// (lbm::Lattice::position; lattice units).
  virtual bool solid_line(int j, int k) const = 0;
  virtual Vec3 node_position(int i, int j, int k) const = 0;
  /// Collective. The velocity and density of the nodes of layer j, index i + nx k (lattice units).
  virtual void layer_fields(int j, std::vector<Vec3>& velocity, std::vector<double>& density) const = 0;
  /// Collective. The mean shear stress on the moving walls of the shear box (lbm/wall_stress.hpp).
  virtual double wall_shear_stress() const = 0;
  /// The walls' shear rate and the kinematic viscosity, lattice units.
  virtual double shear_rate() const = 0;
  virtual double viscosity() const = 0;

 protected:
  /// Throws bendlab::Error for non-positive or non-finite units or sample_every.
  explicit SuspensionSolver(SuspensionSolverOptions options);

  // The suspension, in lattice units.
  virtual int num_cells() const = 0;
  virtual const MembraneModel& cell_membrane(int c) const = 0;
  virtual Eigen::Index cell_first_row(int c) const = 0;
  virtual int add_lattice_cell(std::shared_ptr<const MembraneModel> membrane, const Points& X) = 0;
  virtual void step_suspension() = 0;
  virtual std::int64_t lattice_steps() const = 0;
  /// Collective: every vertex, and the vertex velocities of the last step, cell after cell.
  virtual Points lattice_positions() const = 0;
  virtual Points lattice_velocities() const = 0;
  /// Collective: throws bendlab::Error where the fluid blew up.
  virtual void check_fluid() const = 0;
  /// Collective: the fluid into `file` (flow/lbm/checkpoint.hpp), and back with every vertex X
  /// (lattice units); read_state returns the fluid file's step without changing anything if it
  /// differs from `step`.
  virtual void write_fluid(const std::filesystem::path& file) const = 0;
  virtual std::int64_t read_state(const std::filesystem::path& file, std::int64_t step, const Points& X) = 0;

 private:
  SuspensionSolverOptions options_;
  std::int64_t sample_steps_ = 1;
  Points x_;  // um
  Points u_;  // lattice units
  SolverCounters counters_;
  std::int64_t last_fluid_check_ = 0;
};

}  // namespace bendlab
