#pragma once
// Neo-Hookean in-plane elasticity of a membrane of flat linear triangles (paper section 4.2).
//
//   eps_S = kS/6 (I1 + 1/(I2 + 1) - 1),  I1 = l1^2 + l2^2 - 2,  I2 = l1^2 l2^2 - 1   (eqs. (18), (19))
//   E_S   = sum_t eps_S(t) A0_t                                                     (eq. (20))
//   F_i   = -dE_S/dx_i, exact, analytic                                             (eq. (21))
//
// The reference state is the shape given to the constructor (the initial sphere for the capsule).
// In each triangle the deformation is affine. Its right Cauchy-Green tensor C, written in any
// basis of the reference triangle's plane, has the invariants
//   tr C  = l1^2 + l2^2 = sum_ab (G0^-1)_ab g_ab,    det C = l1^2 l2^2 = (A / A0)^2,
// where g_ab = e_a . e_b and G0_ab = E_a . E_b are the metrics of the current (e) and reference (E)
// edge vectors x1 - x0, x2 - x0. So no local frame is built and the energy is invariant under
// rigid motions by construction; forces therefore sum to zero and exert no torque.
#include "bendlab/core/types.hpp"
#include "bendlab/elasticity/elastic_law.hpp"
#include "bendlab/mesh/topology.hpp"

namespace bendlab {

class NeoHookean final : public ElasticLaw {
 public:
  /// kS: the modulus of eq. (18) (three times the shear modulus, docs/conventions.md §2).
  /// Throws bendlab::Error for a reference triangle of zero area or a non-positive kS.
  NeoHookean(TopologyPtr topology, const Points& reference, double kS);

  std::string name() const override { return "neo-Hookean"; }
  /// E_S of eq. (20) for the current positions x (N x 3).
  double energy(const Points& x) const override;
  /// Node forces F = -dE_S/dx into `force` (resized to N x 3, overwritten). Scratch is allocated
  /// per call: concurrent calls on one object are safe.
  void forces(const Points& x, Points& force) const override;
  /// Energy and forces in one pass; returns E_S.
  double energy_and_forces(const Points& x, Points& force) const override;

  double kS() const override { return kS_; }
  double reference_area() const { return reference_area_; }
  const Topology& topology() const override { return *topology_; }

 private:
  TopologyPtr topology_;
  double kS_;
  double reference_area_ = 0;
  // Per face: A0 and the inverse reference metric (G0^-1)_{00}, _{01}, _{11}.
  Scalars a0_, m00_, m01_, m11_;
};

}  // namespace bendlab
