#include "bendlab/membrane/espresso_volume_force.hpp"

#include <fmt/format.h>

#include <cmath>

#include "bendlab/mesh/enclosed_volume.hpp"

namespace bendlab {

double add_espresso_volume_force(const Topology& topology, const Points& x, double kappa_V, double V0,
                                 Points& forces) {
  if (!(V0 > 0)) throw Error(fmt::format("volume force: reference volume {} must be positive", V0));
  const double V = enclosed_volume(topology, x);
  if (!(V > 0)) throw Error(fmt::format("volume force: enclosed volume {} is not positive (inverted mesh?)", V));
  if (forces.rows() != x.rows()) forces = Points::Zero(x.rows(), 3);
  const double s = -kappa_V * (V - V0) / V;
  const Faces& faces = topology.faces();
  for (Eigen::Index t = 0; t < faces.rows(); ++t) {
    const Vec3 a = row(x, faces(t, 0)), b = row(x, faces(t, 1)), c = row(x, faces(t, 2));
    const Vec3 An = 0.5 * (b - a).cross(c - a);  // A_t n_t
    for (int v = 0; v < 3; ++v) forces.row(faces(t, v)) += s * An.transpose();
  }
  return 3.0 * kappa_V * (V - V0 - V0 * std::log(V / V0));
}

EspressoVolumeForce::EspressoVolumeForce(double kappa_V) : kappa_V_(kappa_V) {
  if (!(kappa_V >= 0) || !std::isfinite(kappa_V))
    throw Error(fmt::format("volume force: kappa_V = {} must be finite and >= 0", kappa_V));
}

std::optional<double> EspressoVolumeForce::energy(const Topology& topology, const Points& x,
                                                  double reference_volume) const {
  Points scratch;
  return add_espresso_volume_force(topology, x, kappa_V_, reference_volume, scratch);
}

void EspressoVolumeForce::add_forces(const Topology& topology, const Points& x, double reference_volume,
                                     Points& force) const {
  add_espresso_volume_force(topology, x, kappa_V_, reference_volume, force);
}

}  // namespace bendlab
