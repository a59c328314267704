#pragma once
// Skalak in-plane elasticity of a membrane of flat linear triangles (Skalak et al. 1973;
// Barthes-Biesel, Diaz & Dhenin, J. Fluid Mech. 460 (2002) 211); not in the paper, which uses the
// neo-Hookean law.
//
//   W   = Gs/4 (I1^2 + 2 I1 - 2 I2) + C Gs/4 I2^2,   I1 = l1^2 + l2^2 - 2,  I2 = l1^2 l2^2 - 1
//   E_S = sum_t W(t) A0_t,   F_i = -dE_S/dx_i (exact, analytic)
//
// Gs = kS/3: kS keeps its meaning of docs/conventions.md section 2 (three times the small-strain
// shear modulus), so a Skalak capsule and a neo-Hookean one with the same G have the same shear
// modulus. For small strains the law is linear elasticity with area-dilatation modulus
// K = Gs (1 + 2C) and surface Poisson ratio nu_s = (K - Gs)/(K + Gs) = C/(1 + C) (Barthes-Biesel
// 2002); C = 1 has the neo-Hookean law's K = 3 Gs, nu_s = 1/2. C > -1/2 keeps K > 0 (the law
// admissible); other C are refused.
//
// The invariants come from the edge metrics exactly as in neo_hookean.hpp:
//   tr C = sum_ab (G0^-1)_ab g_ab,  det C = (A / A0)^2,
// so the energy is invariant under rigid motions by construction.
#include "bendlab/core/types.hpp"
#include "bendlab/elasticity/elastic_law.hpp"
#include "bendlab/mesh/topology.hpp"

namespace bendlab {

class Skalak final : public ElasticLaw {
 public:
  /// kS: three times the shear modulus Gs; C: the area-dilatation parameter (> -1/2).
  /// Throws bendlab::Error for kS <= 0, C <= -1/2, non-finite values or a reference triangle of
  /// zero area.
  Skalak(TopologyPtr topology, const Points& reference, double kS, double C);

  std::string name() const override { return "Skalak"; }
  double energy(const Points& x) const override;
  void forces(const Points& x, Points& force) const override;
  double energy_and_forces(const Points& x, Points& force) const override;

  double kS() const override { return kS_; }
  double C() const { return C_; }
  /// Small-strain surface Poisson ratio C / (1 + C).
  double poisson_ratio() const { return C_ / (1 + C_); }
  const Topology& topology() const override { return *topology_; }

 private:
  TopologyPtr topology_;
  double kS_, C_;
  // Per face: A0 and the inverse reference metric (G0^-1)_{00}, _{01}, _{11}.
  Scalars a0_, m00_, m01_, m11_;
};

}  // namespace bendlab
