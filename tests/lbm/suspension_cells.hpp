#pragma once
// The cells of the suspension tests (serial and MPI): a small red blood cell of eq. (15) and rigid
// moves of its positions.
#include <memory>

#include "bendlab/membrane/espresso_volume_force.hpp"
#include "bendlab/membrane/membrane_model.hpp"
#include "bendlab/mesh/generators.hpp"
#include "bendlab/surfaces/analytic_surface.hpp"

namespace bendlab::test {

// A red blood cell of eq. (15) with a large half-axis of R dx, 320 triangles, stress-free as it
// is, neo-Hookean with modulus kS, no bending, ESPResSo's volume force. The explicit coupling is
// stable while kS / (mu h) stays well below 1 (h the edge length, about 0.3 R; mu = 1/6 at tau = 1):
// kS = 0.01 and below.
inline std::shared_ptr<const MembraneModel> small_rbc(double R, double kS) {
  const TriMesh s = sphere_mesh(MeshFamily::MT1, 2);
  const TriMesh m = s.with_positions(make_rbc(R)->map_from_unit_sphere(s.positions()));
  MembraneParameters p;
  p.kS = kS;
  p.volume_force = std::make_shared<const EspressoVolumeForce>(EspressoVolumeForce::for_membrane(kS));
  return std::make_shared<const MembraneModel>(m, p);
}

// x turned by `angle` about `axis` through the origin, then moved by `by`.
inline Points moved(const Points& x, const Vec3& by, double angle = 0, const Vec3& axis = Vec3::UnitY()) {
  const Mat3 R = Eigen::AngleAxisd(angle, axis).toRotationMatrix();
  Points y = x * R.transpose();
  y.rowwise() += by.transpose();
  return y;
}

}  // namespace bendlab::test
