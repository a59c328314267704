#pragma once
// Method J (Juelicher 1996, as compared with the paper's methods by Bian, Litvinov & Koumoutsakos
// 2020): the edge-based discrete mean curvature and its Helfrich energy, beyond the paper's table 1.
//
//   H_i = 1 / (4 A_i) sum_{edges e at i} l_e theta_e,      A_i = 1/3 sum_{faces f at i} A_f,
//   E   = 2 kB sum_i H_i^2 A_i,                             F = -dE/dx (exact, analytic),
//
// theta_e the signed dihedral angle of edge e: the angle between the outward normals of its two
// faces, positive where the surface is convex (docs/conventions.md §1: H > 0 on a sphere, where
// sum_i H_i A_i = 1/2 sum_e l_e theta_e is Steiner's integrated mean curvature and E -> 8 pi kB).
//
// Consistency: with the barycentric A_i, H_i is exact where the one-ring is made of near-equilateral
// triangles; at a vertex of valence v whose ring on a sphere of radius R is v isosceles triangles
// of apex angle 2 pi / v, H_i R -> 3 / (4 cos^2(pi / v)) at every resolution (1.1459 at the 12
// valence-5 vertices of the MT1 family), so H and f converge in the mean but not in the maximum.
//
// The gradient, derived in julicher.cpp, uses the dihedral angle's derivative through the heights
// of the two faces over the edge, so no division by sin(theta) appears.
//
// Result fields: energy and force as above; area = Meyer's mixed area and force_density = F / area
// (docs/conventions.md §1, eq. (14), as for the other energy methods A and B); H as above;
// normal = the area-weighted vertex normal (sum of the unnormalised face normals, normalised);
// K = the angle deficit (2 pi - sum of corner angles) / A_i with the same barycentric A_i;
// lapH is not defined (NaN).
#include <memory>

#include "bendlab/bending/method_registry.hpp"
#include "bendlab/bending/method_workspace.hpp"

namespace bendlab {

class JulicherMethod : public BendingMethod {
 public:
  JulicherMethod();
  ~JulicherMethod() override;
  /// Takes no options: throws bendlab::Error on any.
  static std::unique_ptr<BendingMethod> create(const MethodOptions& options);
  /// The method's entry in the registry (method_registry.hpp).
  static MethodInfo info();

  std::string name() const override { return "J"; }
  BendingResult compute(const Topology& topology, const Points& x, double kappa_b) const override;
  void compute_into(const Topology& topology, const Points& x, double kappa_b, BendingResult& out) const override;
  void forces(const Topology& topology, const Points& x, double kappa_b, Points& force) const override;
  std::optional<double> energy(const Topology& topology, const Points& x, double kappa_b) const override;

 protected:
  /// c0 and ADE (docs/conventions.md §5): E = 2 kB sum_i (H_i - c0)^2 A_i + E_ADE with the discrete
  /// M = sum_i H_i A_i = 1/2 sum_e l_e theta_e, and its exact gradient.
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
  /// The kernel's per-face, per-edge and per-vertex arrays and compute()'s geometry, kept between calls.
  MethodWorkspace<Workspace> workspace_;
};

}  // namespace bendlab
