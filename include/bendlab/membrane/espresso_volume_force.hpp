#pragma once
// ESPResSo's volume-conservation force of the immersed-boundary capsule (ibm_volcons; technical
// note shared/spec/LBM_IBM.md section 4, after Dupin et al. eq. 9), used with kappa_V = 100 kappa_S
// in the paper's section 4.3.2: one VolumeForce (volume_force.hpp) of a MembraneModel.
// Every triangle t adds -kappa_V (V - V0)/V A_t n_t to each of its three vertices (A_t the full
// area, n_t the outward normal), V = 1/6 sum_t X_a.(X_b x X_c), V0 the reference volume. Because
// sum_{t at a} A_t n_t = 3 dV/dX_a, the force is -3 kappa_V (V - V0)/V dV/dX_a, the exact negative
// gradient of the energy
//   E(V) = 3 kappa_V (V - V0 - V0 ln(V / V0)),   dE/dV = 3 kappa_V (V - V0) / V.
// kappa_V has the units of kS (force per length).
#include <optional>
#include <string>

#include "bendlab/core/types.hpp"
#include "bendlab/membrane/volume_force.hpp"

namespace bendlab {

/// The paper's ratio kappa_V / kappa_S.
inline constexpr double kEspressoVolumeRatio = 100.0;

/// Adds the volume force to `forces` (N x 3, resized and zeroed if its row count differs) and
/// returns the energy E above. Throws bendlab::Error for V0 <= 0 or V <= 0 (an inverted mesh).
double add_espresso_volume_force(const Topology& topology, const Points& x, double kappa_V, double V0, Points& forces);

class EspressoVolumeForce final : public VolumeForce {
 public:
  /// Throws bendlab::Error unless kappa_V >= 0 and finite.
  explicit EspressoVolumeForce(double kappa_V);
  /// kappa_V = ratio * kS (the paper: ratio 100).
  static EspressoVolumeForce for_membrane(double kS, double ratio = kEspressoVolumeRatio) {
    return EspressoVolumeForce(ratio * kS);
  }

  std::string name() const override { return "espresso-volume"; }
  double kappa_V() const { return kappa_V_; }
  std::optional<double> energy(const Topology& topology, const Points& x, double reference_volume) const override;
  void add_forces(const Topology& topology, const Points& x, double reference_volume, Points& force) const override;

 private:
  double kappa_V_;
};

}  // namespace bendlab
