#pragma once
// The boundary integral method for a capsule in linear shear flow (paper section 4), one
// CapsuleSolver. The node velocity is a function of the positions alone, eq. (23):
//   1. f = the membrane model's force density (F / A_mixed, eq. (14));
//   2. u = u_inf + single layer of f (eq. (22), sign of docs/conventions.md), u_inf = gamma z e_x;
//   3. u projected onto the zero discrete flux hyperplane (volume_correction.hpp);
// advanced by an adaptive Integrator (Cash-Karp 4(5) by default, section 4.3.1). After every
// accepted step the shape is rescaled about its volume centroid to the reference volume.
// Units: mu and gamma from BimOptions (1 and 1 for the shear run, shear_units.hpp).
//
// Its checkpoint state is {"dt_next": the step the integrator proposed next} and, for an integrator
// with more state (RKC: controller memory, spectral radius and its vector), {"integrator": {"name",
// "state"}}, so that a resumed run repeats the uninterrupted one step by step. Consecutive
// advance() calls continue one integration; restart() starts a fresh one. Not for concurrent use of one object (the single
// layer keeps per-call quadrature buffers); separate objects are independent.
#include <memory>

#include "bendlab/capsule/capsule_solver.hpp"
#include "bendlab/flow/bim/stokes_single_layer.hpp"
#include "bendlab/integrate/integrator.hpp"
#include "bendlab/membrane/membrane_model.hpp"

namespace bendlab {

struct BimOptions {
  double mu = 1;     ///< viscosity
  double gamma = 1;  ///< shear rate of u_inf = gamma z e_x
  SingleLayerOptions quadrature;
};

class BimCapsuleSolver final : public CapsuleSolver {
 public:
  /// Starts from the membrane's reference shape translated so that its volume centroid sits at the
  /// origin, at time 0. `integrator` nullptr: Cash-Karp with default options. Throws
  /// bendlab::Error for a null membrane or non-positive mu, gamma.
  BimCapsuleSolver(std::shared_ptr<const MembraneModel> membrane, std::unique_ptr<Integrator> integrator = nullptr,
                   BimOptions options = {});

  /// The right-hand side of eq. (23) for positions x: u (N x 3) after the flux projection.
  void velocity(const Points& x, Points& u);

  std::string name() const override { return "bim"; }
  const MembraneModel& membrane() const override { return *membrane_; }
  const Points& positions() const override { return x_; }
  double time() const override { return t_; }
  bool advance(double t_end, const OnStep& on_step) override;
  SolverCounters counters() const override { return counters_; }
  /// {"integrator": name, "integrator_stats": the integrator's summary()} (the latter when not empty).
  nlohmann::json summary() const override;
  SolverState save_state(const std::filesystem::path& folder, const std::string& tag) const override;
  void restore_state(const Points& positions, double time, const SolverCounters& counters,
                     const nlohmann::json& fields, const std::filesystem::path& folder,
                     const std::string& source) override;
  /// dt_next must be 0 before the first step and, after it, positive and at most the integrator's
  /// growth factor times the largest step taken.
  void check_resumed_steps(double largest_step, const std::string& source) const override;

  /// Sets positions (same topology), time and the step to try first (0: the integrator's default).
  void restart(const Points& positions, double time, double dt_next = 0);
  double dt_next() const { return dt_next_; }
  const Integrator& integrator() const { return *integrator_; }
  const BimOptions& options() const { return options_; }

 private:
  std::shared_ptr<const MembraneModel> membrane_;
  std::unique_ptr<Integrator> integrator_;
  BimOptions options_;
  StokesSingleLayer single_layer_;
  Points x_;
  double t_ = 0, dt_next_ = 0;
  nlohmann::json integrator_resume_;  ///< a checkpoint's integrator state to continue from (null: none)
  std::string integrator_resume_source_;
  bool integrator_continues_ = false;  ///< the next advance() continues the last integration
  SolverCounters counters_;
  // Buffers reused by every evaluation (this object is not for concurrent use).
  Points xb_, density_, u_, grad_;
};

}  // namespace bendlab
