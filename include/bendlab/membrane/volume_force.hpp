#pragma once
// Hook for a force that acts on the enclosed volume, e.g. ESPResSo's volume conservation
// (espresso_volume_force.hpp). The membrane model adds its forces to the elastic and bending
// ones when one is given. ESPResSo's form is espresso_volume_force.hpp (the LBM capsule solver's);
// the BIM conserves the volume by the zero-flux projection and rescaling instead
// (volume_correction.hpp).
//
// Implementations are immutable; their const methods must be safe to call concurrently.
#include <optional>
#include <string>

#include "bendlab/core/types.hpp"
#include "bendlab/mesh/topology.hpp"

namespace bendlab {

class VolumeForce {
 public:
  virtual ~VolumeForce() = default;
  virtual std::string name() const = 0;
  /// The energy for positions x, given the reference volume V0 (std::nullopt if not energy-based).
  virtual std::optional<double> energy(const Topology& topology, const Points& x, double reference_volume) const = 0;
  /// Adds the nodal forces of positions x to `force` (N x 3).
  virtual void add_forces(const Topology& topology, const Points& x, double reference_volume, Points& force) const = 0;
};

}  // namespace bendlab
