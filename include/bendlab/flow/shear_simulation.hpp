#pragma once
// An initially spherical capsule in linear shear flow, boundary integral method (paper section 4).
//
// Units: R = 1 (the initial radius), mu = 1, gamma = 1, so time is gamma t and
//   kS = mu gamma R / G,   kB = kappa_b_hat R^2 kS   (CONVENTIONS.md section 2).
// Each evaluation of the right-hand side of eq. (23), dx_i/dt = u(x_i):
//   1. node forces F = F_elastic (neo-Hookean, eq. (21), reference = the initial shape)
//      + F_bending (the given method, if any);
//   2. force density f_i = F_i / A_mixed_i with the mixed area of the current shape (eq. (14));
//   3. u = u_inf + single layer of f (eq. (22) with the sign of CONVENTIONS.md), u_inf = gamma z e_x;
//   4. u projected onto the zero discrete flux hyperplane (volume_correction.hpp).
// Time integration: Cash-Karp 4(5) with rtol, atol (section 4.3.1). After every accepted step the
// shape is rescaled about its volume centroid to the initial volume, then the callback gets a sample.
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>

#include "bendlab/bending/bending_method.hpp"
#include "bendlab/elasticity/neo_hookean.hpp"
#include "bendlab/flow/bim/stokes_single_layer.hpp"
#include "bendlab/integrate/cash_karp.hpp"
#include "bendlab/mesh/trimesh.hpp"

namespace bendlab {

struct ShearParameters {
  double G = 0.1;            ///< mu gamma R / kS
  double kappa_b_hat = 0;    ///< kB / (R^2 kS)
  double t_end = 10;         ///< end time, gamma t
  double rtol = 1e-7;
  double atol = 1e-6;        ///< times R = 1
};

/// What the step callback sees after each accepted (and volume-rescaled) step.
struct ShearSample {
  std::int64_t step = 0;    ///< accepted steps so far (counting from the last run/restart)
  double time = 0;          ///< gamma t
  double dt = 0;            ///< the step just taken
  double dt_next = 0;       ///< the step the integrator proposes next (store it to resume)
  const Points* positions = nullptr;  ///< N x 3, valid during the callback only
  double D = 0, theta = 0;  ///< Taylor deformation and inclination (capsule_shape.hpp)
  double volume = 0, area = 0;
  std::optional<double> E_bend;  ///< bending energy, for energy-based methods
  double E_elastic = 0;
};

class ShearSimulation {
 public:
  /// Returns false to stop the run early (e.g. to write a checkpoint and quit).
  using Callback = std::function<bool(const ShearSample&)>;

  /// `initial` is the reference shape of the elastic law and fixes the volume to conserve; it is
  /// translated so that its volume centroid sits at the origin. `bending` (may be nullptr when
  /// kappa_b_hat = 0) must outlive the simulation. Throws bendlab::Error for invalid parameters.
  ShearSimulation(const TriMesh& initial, ShearParameters params, const BendingMethod* bending = nullptr,
                  SingleLayerOptions quadrature = {});

  /// Resumes from a saved state: positions (same topology as `initial`), gamma t, and optionally
  /// the step size the controller had proposed (0: the integrator's default first step).
  void restart(const Points& positions, double time, double dt_next = 0);

  /// Integrates from the current time to params.t_end. Returns the integrator's statistics.
  CashKarpStats run(const Callback& callback = {});

  /// The right-hand side of eq. (23) for positions x: u (N x 3) after the flux projection.
  void velocity(const Points& x, Points& u);
  /// The sample (D, theta, energies, ...) of positions x, as given to the callback.
  ShearSample sample(const Points& x, double time, double dt, std::int64_t step) const;

  const Points& positions() const { return x_; }
  double time() const { return t_; }
  double dt_next() const { return dt_next_; }
  double kS() const { return kS_; }
  double kB() const { return kB_; }
  double initial_volume() const { return volume0_; }
  const ShearParameters& parameters() const { return params_; }
  const Topology& topology() const { return *topology_; }
  std::int64_t velocity_evaluations() const { return evaluations_; }

 private:
  TopologyPtr topology_;
  ShearParameters params_;
  const BendingMethod* bending_;
  double kS_, kB_, volume0_;
  NeoHookean elastic_;
  StokesSingleLayer single_layer_;
  Points x_;
  double t_ = 0, dt_next_ = 0;
  std::int64_t evaluations_ = 0;
  // Buffers reused by every evaluation.
  Points xb_, force_, fbend_, density_, u_, grad_;
};

}  // namespace bendlab
