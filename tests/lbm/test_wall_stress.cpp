// The walls' shear stress of a shear box (flow/lbm/wall_stress.hpp): mu gamma in the linear shear
// flow, whatever the collision, and nothing for a lattice without walls.
#include <gtest/gtest.h>

#include "bendlab/flow/lbm/wall_stress.hpp"

using namespace bendlab;
using namespace bendlab::lbm;

namespace {
LatticeConfig shear_box(double tau) {
  LatticeConfig c;
  c.nx = 4;
  c.ny = 3;
  c.nz = 8;
  c.tau = tau;
  c.walls = true;
  c.wall_velocity = 0.01;
  return c;
}
}  // namespace

TEST(WallShearStress, IsMuGammaInTheExactShearFlow) {
  Lattice lattice(shear_box(1.0));
  lattice.initialise_shear_flow();
  const double mu_gamma = lattice.viscosity() * lattice.shear_rate();
  EXPECT_NEAR(wall_shear_stress(lattice), mu_gamma, 1e-12 * mu_gamma);
  lattice.run(50);  // a steady state of the scheme: it stays
  EXPECT_NEAR(wall_shear_stress(lattice), mu_gamma, 1e-12 * mu_gamma);
}

// From rest, the walls set the fluid moving; once the flow is linear the stress is mu gamma at
// any tau (here the regularised collision of tau != 1, and TRT), not only where BGK is exact.
TEST(WallShearStress, ReachesMuGammaFromRestAtAnyTau) {
  for (const Collision collision : {Collision::Auto, Collision::TRT}) {
    for (const double tau : {0.8, 1.5}) {
      LatticeConfig c = shear_box(tau);
      c.collision = collision;
      Lattice lattice(c);
      lattice.initialise([](const Vec3&) { return Vec3::Zero(); });
      const double mu_gamma = lattice.viscosity() * lattice.shear_rate();
      EXPECT_LT(wall_shear_stress(lattice), 0.5 * mu_gamma);  // at rest the walls feel no stress yet
      lattice.run(4000);  // about 20 diffusion times nz^2 / nu at tau = 0.8
      EXPECT_NEAR(wall_shear_stress(lattice), mu_gamma, 1e-8 * mu_gamma) << "tau " << tau;
    }
  }
}

TEST(WallShearStress, RefusesALatticeWithoutWalls) {
  LatticeConfig c = shear_box(1.0);
  c.walls = false;
  c.wall_velocity = 0;
  const Lattice lattice(c);
  EXPECT_THROW(wall_shear_stress(lattice), Error);
}
