// Physical units of channel and tube runs (physical_units.hpp): the conversions are exact
// relations, so the tests check them against each other and against a peer's published setup.
#include <gtest/gtest.h>

#include <cmath>

#include "bendlab/flow/lbm/physical_units.hpp"

using namespace bendlab;
using namespace bendlab::lbm;

namespace {

FlowUnitsInput tube(double D, double L, double dx, double tau, double rate) {
  FlowUnitsInput in;
  in.geometry = FlowGeometry::Tube;
  in.diameter_um = D;
  in.length_um = L;
  in.dx_um = dx;
  in.tau = tau;
  in.pseudo_shear_rate = rate;
  return in;
}

}  // namespace

TEST(FlowUnits, TimeStepFollowsFromTauAndTheViscosity) {
  // HemoCell's setup (CELLS_IN_CHANNELS.md section 1): nu = 1.1e-6 m^2/s, dx = 0.5 um, dt = 1e-7 s
  // is tau = 1/2 + 3 nu dt / dx^2 = 1.82.
  FlowUnitsInput in = tube(25, 50, 0.5, 0.5 + 3 * 1.1e-6 * 1e-7 / (0.5e-6 * 0.5e-6), 50);
  in.plasma.density = 1000;
  in.plasma.viscosity = 1.1e-3;
  const FlowUnits u = flow_units(in);
  EXPECT_NEAR(u.dt, 1e-7, 1e-7 * 1e-12);
  EXPECT_EQ(u.nx, 100);
  EXPECT_EQ(u.ny, 54);  // 50 dx and two solid layers on either side
  EXPECT_EQ(u.nz, 54);
  EXPECT_DOUBLE_EQ(u.section_lattice, 50);
  EXPECT_NEAR(u.checked_steps(1e-3, "--t-end"), 1e4, 0);
}

TEST(FlowUnits, StepCountsARunCannotTakeAreRefusedNamingTheOption) {
  const FlowUnits u = flow_units(tube(10, 20, 0.5, 1.0, 100));
  // Rounded up: a run steps to the first step at or past its end.
  EXPECT_EQ(u.checked_steps(2.5 * u.dt, "--t-end"), 3);
  auto message = [&](double seconds, const char* option, bool below_one_ok) {
    try {
      u.checked_steps(seconds, option, below_one_ok);
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(message(1e30, "--t-end", false).find("--t-end 1e+30 s is"), std::string::npos);
  EXPECT_NE(message(FlowUnits::kMaxSteps * 2 * u.dt, "--sample-every", true).find("--sample-every"), std::string::npos);
  EXPECT_NE(message(1e-320, "--t-end", false).find("shorter than one lattice step"), std::string::npos);
  EXPECT_EQ(message(1e-320, "--sample-every", true), "");  // a report every step
  EXPECT_EQ(message(FlowUnits::kMaxSteps * u.dt * 0.5, "--t-end", false), "");
}

TEST(FlowUnits, DrivingsArePoiseuillesLawBothWays) {
  const FlowUnits a = flow_units(tube(10, 20, 0.5, 1.0, 100));
  // v = rate D, g = 32 eta v / D^2.
  EXPECT_NEAR(a.mean_velocity, 100 * 10e-6, 1e-18);
  EXPECT_NEAR(a.body_force, 32 * 1.2e-3 * a.mean_velocity / (10e-6 * 10e-6), 1e-9 * a.body_force);
  FlowUnitsInput by_force = tube(10, 20, 0.5, 1.0, 0);
  by_force.pseudo_shear_rate.reset();
  by_force.body_force = a.body_force;
  const FlowUnits b = flow_units(by_force);
  EXPECT_NEAR(b.pseudo_shear_rate, 100, 1e-10);
  EXPECT_NEAR(b.body_force_lattice, a.body_force_lattice, 1e-15 * a.body_force_lattice);
  // Lattice force g dt^2 / (rho dx); peak velocity 2 v in lattice units; Ma = sqrt(3) u_max.
  EXPECT_NEAR(a.body_force_lattice, a.body_force * a.dt * a.dt / (1025 * 0.5e-6), 1e-15 * a.body_force_lattice);
  EXPECT_NEAR(a.max_velocity_lattice, 2 * a.mean_velocity * a.dt / 0.5e-6, 1e-15);
  EXPECT_NEAR(a.mach, std::sqrt(3.0) * a.max_velocity_lattice, 1e-15);
  // The lattice Poiseuille profile gives the same peak: u_max = g R^2 / (4 nu) in lattice units.
  const double R = 0.5 * a.section_lattice;
  EXPECT_NEAR(a.body_force_lattice * R * R / (4 * a.nu_lattice), a.max_velocity_lattice, 1e-12 * a.max_velocity_lattice);

  FlowUnitsInput ch;
  ch.geometry = FlowGeometry::Channel;
  ch.height_um = 10, ch.width_um = 5, ch.length_um = 20, ch.dx_um = 0.5, ch.tau = 0.8;
  ch.pseudo_shear_rate = 80;
  const FlowUnits c = flow_units(ch);
  EXPECT_EQ(c.nz, 24);  // 20 dx and two solid layers beyond each wall
  EXPECT_EQ(c.ny, 10);
  EXPECT_NEAR(c.body_force, 12 * 1.2e-3 * 80 * 10e-6 / (10e-6 * 10e-6), 1e-9 * c.body_force);
  const double h = 0.5 * c.section_lattice;
  EXPECT_NEAR(c.body_force_lattice * h * h / (2 * c.nu_lattice), c.max_velocity_lattice, 1e-12 * c.max_velocity_lattice);
}

TEST(FlowUnits, RefusesWhatCannotWork) {
  EXPECT_THROW(flow_units(tube(10, 20, 0.5, 0.5, 100)), Error);     // tau = 1/2
  EXPECT_THROW(flow_units(tube(10, 20.2, 0.5, 1.0, 100)), Error);   // length not whole dx
  EXPECT_THROW(flow_units(tube(1.5, 20, 0.5, 1.0, 100)), Error);    // 3 dx across
  EXPECT_THROW(flow_units(tube(-10, 20, 0.5, 1.0, 100)), Error);
  EXPECT_THROW(flow_units(tube(10, 20, 0.5, 1.0, -1)), Error);
  EXPECT_THROW(flow_units(tube(10, 20, 0.5, 1.0, std::nan(""))), Error);
  EXPECT_THROW(flow_units(tube(10, 20, 0.5, 1.0, 1e9)), Error);     // Mach far above 0.1
  FlowUnitsInput both = tube(10, 20, 0.5, 1.0, 100);
  both.body_force = 1e3;
  EXPECT_THROW(flow_units(both), Error);
  FlowUnitsInput none = tube(10, 20, 0.5, 1.0, 100);
  none.pseudo_shear_rate.reset();
  EXPECT_THROW(flow_units(none), Error);
  EXPECT_NO_THROW(flow_units(tube(10, 20, 0.5, 1.0, 0)));           // no driving: fluid at rest
}

TEST(FlowUnits, LatticeConfigHoldsTheTubeAndItsDriving) {
  const FlowUnits u = flow_units(tube(10, 4, 1.0, 0.9, 100));
  const Lattice L(flow_lattice_config(u));
  EXPECT_EQ(L.collision(), Collision::TRT);
  EXPECT_DOUBLE_EQ(L.config().body_force.x(), u.body_force_lattice);
  // The fluid rows are those whose centre lies inside the circle of radius 5 dx.
  int inside = 0;
  for (int k = 0; k < u.nz; ++k) {
    for (int j = 0; j < u.ny; ++j) {
      const Vec3 x = L.position(0, j, k);
      inside += x.y() * x.y() + x.z() * x.z() < 25.0 ? 1 : 0;
    }
  }
  EXPECT_EQ(L.num_fluid_nodes(), static_cast<std::size_t>(inside) * u.nx);
}

// The dimensionless groups of a cell in flow are the same in both unit systems: the capillary
// number eta gamma R / G_s and the reduced bending modulus kB / (R^2 G_s).
TEST(FlowUnits, MembraneModuliKeepTheDimensionlessGroups) {
  const FlowUnits u = flow_units(tube(10, 20, 0.5, 1.3, 150));
  const double R = 3.91e-6, Gs = 5.3e-6, kB = 2e-19;
  const double gamma = u.pseudo_shear_rate;
  const double ca = 1.2e-3 * gamma * R / Gs;
  const double R_lattice = R / u.dx(), gamma_lattice = gamma * u.dt;
  const double ca_lattice = u.nu_lattice * gamma_lattice * R_lattice / u.to_lattice_modulus(Gs);  // rho0 = 1
  EXPECT_NEAR(ca_lattice, ca, 1e-12 * ca);
  EXPECT_NEAR(u.to_lattice_energy(kB) / (R_lattice * R_lattice * u.to_lattice_modulus(Gs)), kB / (R * R * Gs), 1e-12 * kB / (R * R * Gs));
  // A force is a modulus times a length; the body force density a force per volume.
  EXPECT_NEAR(u.to_lattice_force(Gs * R), u.to_lattice_modulus(Gs) * R_lattice, 1e-12 * u.to_lattice_force(Gs * R));
  EXPECT_NEAR(u.to_lattice_force(u.body_force * u.dx() * u.dx() * u.dx()), u.body_force_lattice, 1e-12 * u.body_force_lattice);
}
