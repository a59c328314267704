#pragma once
// Lattice parameters of the capsule-in-shear run (paper section 4.3.2; technical note
// shared/spec/LBM_IBM.md sections 0, 1 and 5). Lattice units dx = dt = 1, rho0 = 1.
//   nu = (tau - 1/2)/3, mu = rho0 nu; box nodes n = round(box/R * R) per axis, walls at z = -+nz/2;
//   Re = R v / nu (the paper's Reynolds number) fixes the wall speed v = Re nu / R,
//   gamma = 2 v / nz, Ma = v sqrt(3), Re_p = gamma R^2 / nu;
//   kS = mu gamma R / G, kB = kB_hat R^2 kS, kV = 100 kS / R (ESPResSo's volume force with
//   kappa_V = 100 kappa_S in the run's units of R, where the membrane model works: its force
//   kappa_V A_t grows with the square of the length unit, so in lattice units it is 100 kS / R);
//   steps = ceil(gamma_t_end / gamma).
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "bendlab/flow/lbm/immersed_boundary.hpp"
#include "bendlab/flow/lbm/lattice.hpp"

namespace bendlab::lbm {

struct CapsuleRunInput {
  double radius = 13.5;        ///< R in dx
  double tau = 1.0;
  double box_x = 9.5, box_y = 9.5, box_z = 19.0;  ///< box edges in multiples of R (z: wall distance)
  double reynolds = 0.26;      ///< Re = R v / nu; the paper keeps Re < 0.3
  double G = 0.05;             ///< mu gamma R / kS
  double kB_hat = 0.0375;      ///< kB / (R^2 kS)
  double kV_over_kS = 100.0;   ///< the paper's kappa_V = 100 kappa_S
  double gamma_t_end = 10.0;
  IbKernel kernel = IbKernel::Phi2;  ///< its half-width counts towards the clearances
  /// The capsule's reach from its centre along x, y, z in multiples of R: 1 for the sphere; a
  /// shape's own (a prolate spheroid of c/a = 4 along x: 2.52, 0.63, 0.63).
  std::array<double, 3> half_extent = {1.0, 1.0, 1.0};
};

struct CapsuleRunParameters {
  int nx = 0, ny = 0, nz = 0;
  double tau = 1.0, nu = 0, mu = 0;
  double wall_velocity = 0, shear_rate = 0;
  double mach = 0, reynolds = 0, particle_reynolds = 0;
  double kS = 0, kB = 0, kV = 0;
  std::int64_t steps = 0;
  /// Non-fatal departures from the paper's setup (Re > 0.3, Ma > 0.01).
  std::vector<std::string> warnings;

  LatticeConfig lattice_config() const;
};

/// Throws bendlab::Error for tau <= 1/2, a non-positive R, G, Re or negative kB_hat, a periodic box
/// axis that cannot hold the capsule (its extent 2 R half_extent plus the kernel support), a
/// capsule touching a wall (nz/2 <= R half_extent_z + kernel half-width), and Ma > 0.1.
CapsuleRunParameters capsule_run_parameters(const CapsuleRunInput& input);

}  // namespace bendlab::lbm
