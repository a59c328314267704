#pragma once
// The last step shared by the variational methods (C, D, E, ED, M): from the per-vertex normal, mean
// curvature H, Gaussian curvature K and Laplace-Beltrami of H, the force density of eq. (10),
//   f = 2 kB (lapH + 2 H (H^2 - K)) n        (Lap = div grad, H > 0 on a sphere: docs/conventions.md),
// and the node force of eq. (14), F = f * A_mixed.
#include "bendlab/bending/bending_method.hpp"
#include "bendlab/bending/method_workspace.hpp"

namespace bendlab {

/// Assembles the result of a variational method (C, D, E, ...) from its per-vertex normal, H, K
/// and lapH: f by eq. (10) with the docs/conventions.md sign, F = f * area by eq. (14). `area` is the
/// mixed area. Moves the inputs into the result; energy stays empty.
/// With c0 or ADE (bending_parameters.hpp, docs/conventions.md §5) f is the general force law
///   f = {2 kB [Lap H + 2 (H - c0)(H^2 + c0 H - K)] - lambda K} n,  lambda = alpha pi kB (M - M0) / A,
/// with the discrete M = sum_i H_i A_mixed_i; plain parameters take eq. (10)'s loop unchanged.
BendingResult assemble_variational_result(Points normal, Scalars H, Scalars K, Scalars lapH, Scalars area,
                                          const BendingParameters& p);

/// The same arithmetic into force_density and force (resized; no allocation when they have the size).
void assemble_variational_forces(const Points& normal, const Scalars& H, const Scalars& K, const Scalars& lapH,
                                 const Scalars& area, const BendingParameters& p, Points& force_density,
                                 Points& force);

/// A method of this family: it provides the fields (normal, H, K, lapH, area) of a shape, and this
/// class does the rest, with and without c0 / ADE: compute, compute_into, forces (into a kept
/// workspace, so that forces allocates nothing once warm) and their *_terms forms.
class VariationalMethod : public BendingMethod {
 public:
  BendingResult compute(const Topology& topology, const Points& x, double kappa_b) const override;
  void compute_into(const Topology& topology, const Points& x, double kappa_b, BendingResult& out) const override;
  void forces(const Topology& topology, const Points& x, double kappa_b, Points& force) const override;

 protected:
  /// c0 and ADE through the force law of docs/conventions.md §5.
  bool supports_membrane_terms() const override { return true; }
  BendingResult compute_terms(const Topology& topology, const Points& x, const BendingParameters& params) const override;
  void compute_terms_into(const Topology& topology, const Points& x, const BendingParameters& params,
                          BendingResult& out) const override;
  void forces_terms(const Topology& topology, const Points& x, const BendingParameters& params,
                    Points& force) const override;

  /// Sets out.normal, out.H, out.K, out.lapH and out.area (resized to the mesh, reusing their
  /// storage) for the shape x; the other fields are left alone.
  virtual void fields(const Topology& topology, const Points& x, BendingResult& out) const = 0;

 private:
  void evaluate(const Topology& topology, const Points& x, const BendingParameters& params, BendingResult& out) const;
  /// forces(): the fields and f of the last call.
  MethodWorkspace<BendingResult> forces_workspace_;
};

}  // namespace bendlab
