// The distributed fluid against the serial Lattice: the same density and velocity at every node
// after 100 (and 101: the other AA parity) steps of a non-trivial flow with a force field, between
// moving walls and fully periodic, BGK and regularised; and a checkpoint written by all ranks is
// the serial checkpoint and continues on half the ranks.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "bendlab/flow/lbm/checkpoint.hpp"
#include "bendlab/parallel/distributed_checkpoint.hpp"
#include "bendlab/parallel/distributed_lattice.hpp"
#include "mpi_test_util.hpp"

using namespace bendlab;
using namespace bendlab::parallel;
using bendlab::test::max_over_ranks;

namespace {

constexpr double kPi = std::numbers::pi;

lbm::LatticeConfig config(bool walls, double tau) {
  lbm::LatticeConfig c;
  c.nx = 6;
  c.ny = 12;  // 12, 6, 4, 3 layers per rank for 1 to 4 ranks
  c.nz = 5;
  c.tau = tau;
  c.walls = walls;
  c.wall_velocity = walls ? 0.03 : 0.0;
  return c;
}

// A flow that varies along every axis, so that every population crosses the slab faces.
Vec3 velocity(const Vec3& x, const lbm::LatticeConfig& c) {
  return {0.02 * std::sin(2 * kPi * x.y() / c.ny) + 0.01 * std::cos(2 * kPi * x.z() / c.nz),
          0.015 * std::cos(2 * kPi * x.x() / c.nx) * std::sin(2 * kPi * x.z() / c.nz),
          0.01 * std::sin(2 * kPi * (x.x() / c.nx + x.y() / c.ny))};
}
double density(const Vec3& x, const lbm::LatticeConfig& c) { return 1.0 + 0.01 * std::cos(2 * kPi * x.y() / c.ny + x.x()); }
Vec3 force(const Vec3& x, const lbm::LatticeConfig& c) {
  return 1e-4 * Vec3(std::cos(2 * kPi * x.y() / c.ny), std::sin(x.x() + x.z()), std::cos(2 * kPi * x.y() / c.ny + x.z()));
}

void set_force(lbm::Lattice& serial, const lbm::LatticeConfig& c) {
  serial.clear_force();
  for (int k = 0; k < c.nz; ++k)
    for (int j = 0; j < c.ny; ++j)
      for (int i = 0; i < c.nx; ++i) serial.add_force(serial.index(i, j, k), force(serial.position(i, j, k), c));
}
void set_force(DistributedLattice& d) {
  const lbm::LatticeConfig& c = d.config();
  d.local().clear_force();
  for (int k = 0; k < c.nz; ++k)
    for (int j = d.slab().begin; j < d.slab().begin + d.slab().count; ++j)
      for (int i = 0; i < c.nx; ++i) d.local().add_force(d.local_node(i, j, k), force(d.position(i, j, k), c));
}

// Largest difference of rho and u over the owned nodes of all ranks (collective).
double field_difference(const DistributedLattice& d, const lbm::Lattice& serial) {
  const lbm::LatticeConfig& c = d.config();
  double e = 0;
  for (int k = 0; k < c.nz; ++k)
    for (int j = d.slab().begin; j < d.slab().begin + d.slab().count; ++j)
      for (int i = 0; i < c.nx; ++i) {
        const std::size_t a = d.local_node(i, j, k), b = serial.index(i, j, k);
        e = std::max(e, std::abs(d.local().density(a) - serial.density(b)));
        e = std::max(e, (d.local().velocity(a) - serial.velocity(b)).cwiseAbs().maxCoeff());
      }
  return max_over_ranks(e, d.comm());
}

struct Case {
  bool walls;
  double tau;
};

class DistributedFluid : public ::testing::TestWithParam<Case> {};

}  // namespace

TEST_P(DistributedFluid, MatchesTheSerialLatticeAfter100Steps) {
  const lbm::LatticeConfig c = config(GetParam().walls, GetParam().tau);
  lbm::Lattice serial(c);
  DistributedLattice d(c, MPI_COMM_WORLD);
  serial.initialise([&](const Vec3& x) { return velocity(x, c); }, [&](const Vec3& x) { return density(x, c); });
  d.initialise([&](const Vec3& x) { return velocity(x, c); }, [&](const Vec3& x) { return density(x, c); });
  set_force(serial, c);
  set_force(d);
  EXPECT_EQ(field_difference(d, serial), 0.0);  // the same initial state, node by node
  for (int s = 0; s < 100; ++s) {
    serial.step();
    d.step();
  }
  // The flow has moved: the comparison is not of two states at rest.
  lbm::Lattice initial(c);
  initial.initialise([&](const Vec3& x) { return velocity(x, c); }, [&](const Vec3& x) { return density(x, c); });
  set_force(initial, c);
  EXPECT_GT(field_difference(d, initial), 1e-4);
  // The owned nodes hold the serial populations: the fields are equal bit for bit (the acceptance
  // bound is 1e-13).
  EXPECT_EQ(field_difference(d, serial), 0.0);
  serial.step();
  d.step();
  EXPECT_EQ(field_difference(d, serial), 0.0);  // odd step count: the ghost layers are read
  EXPECT_EQ(d.step_count(), 101);
  EXPECT_EQ(d.halo_doubles_sent(), 101 * 2 * 5 * c.nx * c.nz);
  EXPECT_NEAR(d.total_mass(), serial.total_mass(), 1e-11 * c.nx * c.ny * c.nz);
}

INSTANTIATE_TEST_SUITE_P(WallsAndCollisions, DistributedFluid,
                         ::testing::Values(Case{true, 1.0}, Case{true, 0.8}, Case{false, 1.0}, Case{false, 0.65}));

TEST(DistributedCheckpoint, IsTheSerialFileAndRestartsOnHalfTheRanks) {
  const bendlab::test::SharedFolder folder;
  const lbm::LatticeConfig c = config(true, 0.8);
  lbm::Lattice serial(c);
  DistributedLattice d(c, MPI_COMM_WORLD);
  serial.initialise([&](const Vec3& x) { return velocity(x, c); }, [&](const Vec3& x) { return density(x, c); });
  d.initialise([&](const Vec3& x) { return velocity(x, c); }, [&](const Vec3& x) { return density(x, c); });
  set_force(serial, c);
  set_force(d);
  for (int s = 0; s < 37; ++s) {  // odd: the AA layout that streams
    serial.step();
    d.step();
  }
  const auto path = folder.path() / "fluid.bin";
  write_checkpoint(d, path);
  EXPECT_FALSE(std::filesystem::exists(folder.path() / "fluid.bin.tmp"));
  // The serial reader reads it, and it holds the serial lattice's raw populations exactly.
  lbm::Lattice read(c);
  lbm::read_checkpoint(read, path);
  EXPECT_EQ(read.step_count(), 37);
  EXPECT_TRUE(read.raw_populations() == serial.raw_populations());
  // The serial writer's file, read by the ranks, continues as the distributed lattice did.
  if (bendlab::test::world_rank() == 0) lbm::write_checkpoint(serial, folder.path() / "serial.bin");
  MPI_Barrier(MPI_COMM_WORLD);
  {
    DistributedLattice e(c, MPI_COMM_WORLD);
    read_checkpoint(e, folder.path() / "serial.bin");
    set_force(e);
    EXPECT_EQ(field_difference(e, serial), 0.0);
  }
  // Half the ranks (at least one) continue from the file for 63 steps.
  const int half = std::max(1, bendlab::test::world_size() / 2);
  for (int s = 0; s < 63; ++s) serial.step();
  const bendlab::test::SubComm sub(half);
  if (sub.get() != MPI_COMM_NULL) {
    DistributedLattice h(c, sub.get());
    read_checkpoint(h, path);
    EXPECT_EQ(h.step_count(), 37);
    set_force(h);
    for (int s = 0; s < 63; ++s) h.step();
    EXPECT_EQ(field_difference(h, serial), 0.0);
  }
  MPI_Barrier(MPI_COMM_WORLD);
}

TEST(DistributedCheckpoint, RefusesAnotherLatticeOnEveryRank) {
  const bendlab::test::SharedFolder folder;
  lbm::LatticeConfig c = config(true, 1.0);
  DistributedLattice d(c, MPI_COMM_WORLD);
  write_checkpoint(d, folder.path() / "fluid.bin");
  c.nz = 6;
  DistributedLattice other(c, MPI_COMM_WORLD);
  EXPECT_THROW(read_checkpoint(other, folder.path() / "fluid.bin"), Error);
  EXPECT_THROW(read_checkpoint(other, folder.path() / "missing.bin"), Error);
}

namespace {

// A tube along x whose circular wall cuts the slab faces at every rank count of the suite (1 to 4
// ranks: 12 to 3 layers each), with links at every wall fraction, TRT and a body force as the
// flow command drives it, and the interpolated bounce-back (or the plain one).
lbm::LatticeConfig tube_config(bool interpolated) {
  lbm::LatticeConfig c;
  c.nx = 5;
  c.ny = 12;
  c.nz = 12;
  c.tau = 0.9;
  c.walls = false;
  c.collision = lbm::Collision::TRT;
  c.body_force = Vec3(2e-5, 0.0, 0.0);
  c.section = std::make_shared<lbm::TubeWall>(5.3);
  c.interpolated_walls = interpolated;
  return c;
}

// A velocity field with components across the section, zero in the solid (Lattice::initialise
// keeps solid rows at rest).
Vec3 tube_velocity(const Vec3& x) {
  return {0.01 * (1 - (x.y() * x.y() + x.z() * x.z()) / 28.0), 0.004 * std::sin(x.x() + x.z()), 0.003 * std::cos(x.y() - x.x())};
}

// Both lattices in the same initial state with the same force field.
void start(lbm::Lattice& serial, DistributedLattice& d) {
  serial.initialise(tube_velocity);
  d.initialise(tube_velocity);
  set_force(serial, serial.config());
  set_force(d);
}

void step_both(lbm::Lattice& serial, DistributedLattice& d, int steps) {
  for (int s = 0; s < steps; ++s) {
    serial.step();
    d.step();
  }
}

}  // namespace

TEST(DistributedTube, MatchesTheSerialLatticeBitForBitWithInterpolatedWalls) {
  for (const bool interpolated : {true, false}) {
    const lbm::LatticeConfig c = tube_config(interpolated);
    lbm::Lattice serial(c);
    DistributedLattice d(c, MPI_COMM_WORLD);
    start(serial, d);
    EXPECT_EQ(field_difference(d, serial), 0.0);
    step_both(serial, d, 60);
    lbm::Lattice initial(c);
    initial.initialise(tube_velocity);
    set_force(initial, c);
    EXPECT_GT(field_difference(d, initial), 1e-4) << "interpolated " << interpolated;
    EXPECT_EQ(field_difference(d, serial), 0.0) << "interpolated " << interpolated;
    step_both(serial, d, 1);
    EXPECT_EQ(field_difference(d, serial), 0.0) << "interpolated " << interpolated << ", odd step";
    EXPECT_NEAR(d.total_mass(), serial.total_mass(), 1e-11 * c.nx * c.ny * c.nz);
  }
}

TEST(DistributedTube, CheckpointIsTheSerialFileSolidRowsIncluded) {
  const bendlab::test::SharedFolder folder;
  const lbm::LatticeConfig c = tube_config(true);
  lbm::Lattice serial(c);
  DistributedLattice d(c, MPI_COMM_WORLD);
  start(serial, d);
  step_both(serial, d, 41);
  const auto path = folder.path() / "tube.bin";
  write_checkpoint(d, path);
  lbm::Lattice read(c);
  lbm::read_checkpoint(read, path);
  EXPECT_EQ(read.step_count(), 41);
  // Every population of every node, the solid rows' resting ones too.
  EXPECT_TRUE(read.raw_populations() == serial.raw_populations());
  // Half the ranks continue from it as the serial lattice does.
  const int half = std::max(1, bendlab::test::world_size() / 2);
  for (int s = 0; s < 23; ++s) serial.step();
  const bendlab::test::SubComm sub(half);
  if (sub.get() != MPI_COMM_NULL) {
    DistributedLattice h(c, sub.get());
    read_checkpoint(h, path);
    set_force(h);
    for (int s = 0; s < 23; ++s) h.step();
    EXPECT_EQ(field_difference(h, serial), 0.0);
  }
  MPI_Barrier(MPI_COMM_WORLD);
}
