#pragma once
// Method A (Kantor and Nelson; paper section 2.3.1): the dihedral-angle energy of eq. (6),
//
//   E = 2 kB~ sum_<ij> (1 - cos theta_ij),   kB~ = sqrt(3) kB,
//
// the sum running once over the edges, theta_ij the angle between the unit normals of the two
// faces of edge <ij>. With small_angle, cos theta ~ 1 - theta^2 / 2, i.e. E = kB~ sum theta_ij^2.
// F = -dE/dx (eq. (5)) is the exact analytic gradient.
//
// On a sphere tiled by equilateral triangles of edge a, theta ~ a / (sqrt(3) R) and there are
// 3/2 N_T edges with N_T ~ 16 pi R^2 / (sqrt(3) a^2), so E -> kB~ 8 pi / sqrt(3) = 8 pi kB; this is
// where kB~ = sqrt(3) kB comes from. Other triangulations converge to other values: on MT1 spheres
// E approaches 8 pi kB from above to within 0.2%, on MT2 spheres about 4% above, on the
// octahedron family more than 20% above (test SphereEnergyConvergesToATriangulationDependentLimit).
//
// Result fields: force and energy as above; area = Meyer's mixed area; force_density = F / area
// (eq. (14)); normal = the angle-weighted (MWA) vertex normal, which the energy itself does not
// use but which is the normal a caller projecting f onto n needs; H, K, lapH are not defined by
// the method and are NaN.
#include <memory>

#include "bendlab/bending/method_registry.hpp"
#include "bendlab/bending/method_workspace.hpp"

namespace bendlab {

class KantorNelson : public BendingMethod {
 public:
  explicit KantorNelson(bool small_angle = false);
  ~KantorNelson() override;
  /// Options: "small_angle" = true|false|1|0. Throws bendlab::Error on any other option or value.
  static std::unique_ptr<BendingMethod> create(const MethodOptions& options);
  /// The method's entry in the registry (method_registry.hpp): description, options, capabilities.
  static MethodInfo info();

  std::string name() const override { return "A"; }
  bool small_angle() const { return small_angle_; }

  BendingResult compute(const Topology& topology, const Points& x, double kappa_b) const override;
  void compute_into(const Topology& topology, const Points& x, double kappa_b, BendingResult& out) const override;
  void forces(const Topology& topology, const Points& x, double kappa_b, Points& force) const override;
  std::optional<double> energy(const Topology& topology, const Points& x, double kappa_b) const override;

 private:
  struct Workspace;
  /// Fills force (resized to N x 3) and returns the energy.
  double energy_and_forces(const Topology& topology, const Points& x, double kappa_b, Points& force,
                           Workspace& ws) const;

 protected:
  /// A is refused c0 and ADE (docs/conventions.md §5): see membrane_terms_refusal().
  std::string membrane_terms_refusal() const override;

 private:
  bool small_angle_;
  /// The kernel's scratch arrays and compute()'s geometry, kept between calls.
  MethodWorkspace<Workspace> workspace_;
};

}  // namespace bendlab
