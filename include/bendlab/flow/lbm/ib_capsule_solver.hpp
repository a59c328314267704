#pragma once
// What every immersed-boundary lattice Boltzmann capsule solver shares (paper section 4.3.2;
// technical note shared/spec/LBM_IBM.md), whatever holds its fluid: the serial lattice
// (LbmCapsuleSolver) or one slab of it per MPI rank (parallel::MpiLbmCapsuleSolver). One lattice
// step is one IB step in ESPResSo's order:
//   1. F = the membrane model's nodal forces at X(t) (elastic + bending + volume force);
//   2. spread F onto the lattice; 3. collide (Guo) and stream; 4. interpolate u and move X (Euler).
// This class does 1 and everything around the step; a fluid does 2-4 (ib_step).
//
// Units. The membrane model is in the shear run's units (shear_units.hpp: R = mu = gamma = 1,
// kS = 1/G); the solver keeps the nodes in lattice units, X = R x (R in dx, the capsule centred on
// the box centre), and scales the forces by mu gamma R^2 in lattice units (F_lattice =
// nu gamma_lattice R^2 F, rho0 = 1), which maps kS = 1/G to kS = mu gamma R / G and keeps G and
// kappa_b_hat. positions() and time() are in the run's units: x = X / R and gamma t = steps
// gamma_lattice.
//
// Accepted steps. Reporting every lattice step would make the time series enormous (4e5 steps for
// the paper's case), so on_step is called every `sample_steps` lattice steps (the run's
// sample_every in gamma t, rounded to whole steps, at least 1) and at the step that reaches t_end;
// AcceptedStep::dt is the gamma t since the previous report. A run's checkpoints therefore fall on
// reported steps.
//
// Blow-up. Node positions are checked after every step and the whole fluid (check_fluid) every
// kFluidCheckSteps steps and before every save_state: a non-finite node position, a node whose
// kernel reaches a wall, or a non-finite or non-positive density throws bendlab::Error naming the
// lattice step and the membrane node or lattice node, before the step is reported, so the run's
// last checkpoint stays the last good state.
//
// Checkpoint state: {"fluid": "lbm_fluid_<tag>.bin" (lbm/checkpoint.hpp, written atomically),
// "lattice_step": n, "positions_lattice": [3N numbers, X in dx]} so that a resumed run repeats
// the uninterrupted one bit for bit (X is kept in lattice units; X / R * R would round).
// Not for concurrent use of one object.
#include <cstdint>
#include <filesystem>
#include <memory>

#include "bendlab/capsule/capsule_solver.hpp"
#include "bendlab/flow/lbm/immersed_boundary.hpp"
#include "bendlab/flow/lbm/parameters.hpp"
#include "bendlab/membrane/membrane_model.hpp"

namespace bendlab {

struct LbmSolverOptions {
  double radius = 6;                            ///< R in dx (the same as the parameters' input)
  lbm::CapsuleRunParameters lattice;            ///< from lbm::capsule_run_parameters()
  lbm::IbKernel kernel = lbm::IbKernel::Phi2;
  double sample_every = 1e-3;                   ///< gamma t between reported steps (>= 1 lattice step)
  /// The capsule's volume centroid at the start, in dx from the box centre (a cell corner of
  /// the lattice: nodes sit at half-integer coordinates). Each component within [-1, 1]: it moves
  /// the capsule against the lattice (a measure of the immersed boundary's dependence on where
  /// the surface meets the nodes), not in the flow; a z offset carries it along x at gamma z.
  Vec3 offset = Vec3::Zero();
};

class IbCapsuleSolver : public CapsuleSolver {
 public:
  static constexpr std::int64_t kFluidCheckSteps = 1000;

  std::string name() const override { return "lbm"; }
  const MembraneModel& membrane() const override { return *membrane_; }
  const Points& positions() const override { return x_; }
  double time() const override { return static_cast<double>(fluid_step_count()) * gamma_; }
  bool advance(double t_end, const OnStep& on_step) override;
  SolverCounters counters() const override { return counters_; }
  SolverState save_state(const std::filesystem::path& folder, const std::string& tag) const override;
  void restore_state(const Points& positions, double time, const SolverCounters& counters,
                     const nlohmann::json& fields, const std::filesystem::path& folder,
                     const std::string& source) override;
  /// lbm_fluid_NNNNN.bin, the fluid of a checkpoint.
  bool is_side_file(const std::string& name) const override;

  /// One lattice step (steps 1-4 above) without reporting; throws on blow-up.
  void step();

  /// Node positions in dx (box centred on the origin).
  const Points& lattice_positions() const { return X_; }
  const LbmSolverOptions& options() const { return options_; }
  /// Lattice steps between reports.
  std::int64_t sample_steps() const { return sample_steps_; }
  /// Lattice force per unit of the membrane model's force: nu gamma_lattice R^2.
  double force_scale() const { return force_scale_; }

 protected:
  /// Checks the membrane (not null) and the options (positive radius and sample_every, a lattice
  /// with shear); throws bendlab::Error naming the problem.
  IbCapsuleSolver(std::shared_ptr<const MembraneModel> membrane, LbmSolverOptions options);

  /// For the derived constructor, once its fluid exists (before it starts the shear flow): the
  /// membrane's reference shape with its volume centroid at the box centre plus options.offset,
  /// time 0. Throws if an offset component is outside [-1, 1] or a node's kernel reaches a wall.
  void place_capsule(double shear_rate, double viscosity);

  /// The fluid's lattice step count.
  virtual std::int64_t fluid_step_count() const = 0;
  /// Steps 2-4: spread F (lattice units) from X, one fluid step, interpolate U at X, move X.
  virtual void ib_step(Points& X, const Points& F, Points& U) = 0;
  /// Throws bendlab::Error naming the first lattice node with a non-finite or non-positive density.
  virtual void check_fluid() const = 0;
  /// Writes the fluid to `file` (atomically).
  virtual void write_fluid(const std::filesystem::path& file) const = 0;
  /// Reads the fluid from `file`; it replaces the present fluid only when it is at lattice step
  /// `step`. Returns the file's step. Throws bendlab::Error for an unreadable or mismatched file.
  virtual std::int64_t read_fluid(const std::filesystem::path& file, std::int64_t step) = 0;

 private:
  std::shared_ptr<const MembraneModel> membrane_;
  LbmSolverOptions options_;
  double gamma_ = 0, force_scale_ = 0;
  std::int64_t sample_steps_ = 1;
  Points X_, x_;         // lattice units, run units
  Points F_, U_;         // scratch: forces, node velocities
  SolverCounters counters_;
  std::int64_t last_fluid_check_ = 0;
};

}  // namespace bendlab
