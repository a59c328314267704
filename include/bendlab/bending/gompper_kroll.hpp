#pragma once
// Method B (Gompper and Kroll; paper section 2.3.2 and Appendix A): the cotangent discretisation
// of eq. (1),
//
//   E = kB/2 sum_i (2 H_i)^2 A_i,  (2 H_i)^2 = |S_i|^2 / (2 A_i)^2,  S_i = sum_j T_ij (x_i - x_j),
//
// (eqs. (7), (8)) with T_ij = cot + cot of the two corners opposite edge <ij> (eq. (A.3)) and A_i
// the Voronoi area of eq. (9), A_i = 1/8 sum_j T_ij |x_i - x_j|^2, taken for every triangle, obtuse
// or not. So E = kB sum_i |S_i|^2 / D_i with D_i = 8 A_i, i.e. eqs. (A.1)-(A.2). F = -dE/dx
// (eq. (5)) is the exact analytic gradient (Appendix A; see the .cpp for how it is organised).
//
// Result fields: force, energy; area = Meyer's mixed area; force_density = F / area (eq. (14));
// normal = the angle-weighted (MWA) vertex normal; H = sign(S_i . n_i) |S_i| / (4 A_i), i.e. the
// magnitude the energy uses (|Lap x| / 2 with the Voronoi area) with the sign of
// -1/2 (Lap x) . n, so that E = 2 kB sum_i H_i^2 A_i exactly and H > 0 on a sphere;
// K = angle defect / mixed area (eq. (12)); lapH is not defined by the method and is NaN.
#include <memory>

#include "bendlab/bending/method_registry.hpp"
#include "bendlab/bending/method_workspace.hpp"

namespace bendlab {

class GompperKroll : public BendingMethod {
 public:
  GompperKroll();
  ~GompperKroll() override;
  /// Method B has no options; throws bendlab::Error for any option given.
  static std::unique_ptr<BendingMethod> create(const MethodOptions& options);
  /// The method's entry in the registry (method_registry.hpp): description, options, capabilities.
  static MethodInfo info();

  std::string name() const override { return "B"; }

  BendingResult compute(const Topology& topology, const Points& x, double kappa_b) const override;
  void compute_into(const Topology& topology, const Points& x, double kappa_b, BendingResult& out) const override;
  void forces(const Topology& topology, const Points& x, double kappa_b, Points& force) const override;
  std::optional<double> energy(const Topology& topology, const Points& x, double kappa_b) const override;

 protected:
  /// c0 and ADE (docs/conventions.md §5): E = 2 kB sum_i (H_i - c0)^2 A_i + E_ADE with the signed
  /// H_i = sign(S_i . N_i) |S_i| / (4 A_i) (N_i the area-weighted normal), M = sum_i H_i A_i, and
  /// its exact gradient (gompper_kroll.cpp). H in the result has that sign.
  bool supports_membrane_terms() const override { return true; }
  BendingResult compute_terms(const Topology& topology, const Points& x, const BendingParameters& p) const override;
  void compute_terms_into(const Topology& topology, const Points& x, const BendingParameters& p,
                          BendingResult& out) const override;
  void forces_terms(const Topology& topology, const Points& x, const BendingParameters& p,
                    Points& force) const override;
  std::optional<double> energy_terms(const Topology& topology, const Points& x,
                                     const BendingParameters& p) const override;

 private:
  struct Workspace;
  /// The kernel's scratch arrays, its per-vertex sums and compute()'s geometry, kept between calls.
  MethodWorkspace<Workspace> workspace_;
};

}  // namespace bendlab
