// Many cells over MPI ranks (parallel/mpi_suspension.hpp): each rank owns whole cells, and the
// run equals the serial suspension (flow/lbm/lbm_suspension.hpp) bit for bit, positions and fluid,
// on any number of ranks: cells that touch each other and the tube's wall, cross slab faces (and
// so change owners) and leave the box along the flow.
#include <gtest/gtest.h>

#include <algorithm>
#include <memory>

#include "bendlab/flow/lbm/lbm_suspension.hpp"
#include "bendlab/flow/lbm/section_walls.hpp"
#include "bendlab/parallel/mpi_suspension.hpp"
#include "lbm/suspension_cells.hpp"
#include "parallel/mpi_test_util.hpp"

using namespace bendlab;
using namespace bendlab::lbm;
using bendlab::parallel::MpiSuspension;

namespace {

using test::small_rbc;

Points moved(const Points& x, const Vec3& by, double turn_about_x = 0) { return test::moved(x, by, turn_about_x, Vec3::UnitX()); }

// A tube of radius 9 dx along x, 32 dx long, driven by a body force, with cell-cell and wall
// repulsion and a push on every vertex towards +y.
SuspensionOptions tube_options() {
  SuspensionOptions o;
  o.lattice.nx = 32;
  o.lattice.ny = 22;
  o.lattice.nz = 22;
  o.lattice.tau = 0.9;
  o.lattice.walls = false;
  o.lattice.collision = Collision::TRT;
  o.lattice.body_force = Vec3(1e-4, 0.0, 0.0);
  o.lattice.section = std::make_shared<TubeWall>(9.0);
  o.lattice.interpolated_walls = true;
  o.vessel = Vessel::tube(18.0, 32.0);
  o.cell_contact = ContactLaw{0.02, 1.5};
  o.wall_contact = ContactLaw{0.02, 1.5};
  o.vertex_force = Vec3(0.0, 3e-4, 0.0);
  return o;
}

// Four cells side by side along the flow, 8 dx apart (their repulsion reaches across the gaps),
// with their centroids 0.04 dx below slab faces of 2, 3 and 4 ranks over 22 layers (y = 0; -3,
// 4; -5, 1, 6; the push moves them about 0.1 dx in 61 steps), the last one just short of the
// box's end along x, and the lowest close to the wall.
template <class Suspension>
void add_cells(Suspension& s, const std::shared_ptr<const MembraneModel>& m) {
  const Points& x = m->reference_positions();
  s.add_cell(m, moved(x, Vec3(-8.1, -5.04, 0.3)));
  s.add_cell(m, moved(x, Vec3(-0.1, -3.04, -0.4), 0.4));
  s.add_cell(m, moved(x, Vec3(7.9, -0.04, 0.2), -0.3));
  s.add_cell(m, moved(x, Vec3(15.9, 0.96, -0.2), 1.5));
}

// The largest difference of density and velocity over this rank's layers, over all ranks.
double fluid_difference(const MpiSuspension& d, const LbmSuspension& serial) {
  const LatticeConfig& g = d.fluid().config();
  const auto& slab = d.fluid().slab();
  double m = 0;
  for (int k = 0; k < g.nz; ++k)
    for (int j = slab.begin; j < slab.begin + slab.count; ++j)
      for (int i = 0; i < g.nx; ++i) {
        const std::size_t a = d.fluid().local_node(i, j, k), b = serial.lattice().index(i, j, k);
        m = std::max(m, std::abs(d.fluid().local().density(a) - serial.lattice().density(b)));
        m = std::max(m, (d.fluid().local().velocity(a) - serial.lattice().velocity(b)).cwiseAbs().maxCoeff());
      }
  return bendlab::test::max_over_ranks(m);
}

}  // namespace

TEST(MpiSuspension, TubeEqualsTheSerialSuspensionBitForBit) {
  const auto m = small_rbc(3.5, 0.005);
  LbmSuspension serial(tube_options());
  MpiSuspension d(tube_options(), MPI_COMM_WORLD);
  add_cells(serial, m);
  add_cells(d, m);
  ASSERT_EQ(d.gather_positions(), serial.positions());
  const int ranks = bendlab::test::world_size();
  int owner_changes = 0, wrapped = 0, most_held = 0;
  std::vector<int> last_owner(4, -2);
  for (int step = 0; step < 61; ++step) {
    const Points before = serial.positions();
    serial.step();
    d.step();
    // Every cell has one owner, and only it moves the cell; count the hand-overs.
    for (int c = 0; c < 4; ++c) {
      int here = d.owner(c) == bendlab::test::world_rank() ? 1 : 0, owners = 0;
      MPI_Allreduce(&here, &owners, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
      ASSERT_EQ(owners, 1) << "cell " << c << " at step " << step + 1;
      int owner = d.owner(c) == bendlab::test::world_rank() ? bendlab::test::world_rank() : -1, global = -1;
      MPI_Allreduce(&owner, &global, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
      if (last_owner[c] >= 0 && global != last_owner[c]) ++owner_changes;
      last_owner[c] = global;
      const Eigen::Index rows = serial.rows(c), first = serial.first_row(c);
      if (std::abs(serial.positions().middleRows(first, rows).col(0).mean() - before.middleRows(first, rows).col(0).mean()) > 16)
        ++wrapped;
    }
    most_held = std::max(most_held, static_cast<int>(d.held_cells().size()));
  }
  EXPECT_EQ(d.gather_positions(), serial.positions());
  EXPECT_EQ(fluid_difference(d, serial), 0.0);
  EXPECT_EQ(d.steps(), serial.steps());
  // What the test is meant to exercise happened: contact with neighbours and the wall, a cell
  // across the periodic end, and (on more than one rank) cells changing hands and ghosts.
  EXPECT_GT(serial.cell_contact_energy(), 0.0);
  EXPECT_GT(serial.wall_contact_energy(), 0.0);
  EXPECT_GE(wrapped, 1);
  if (ranks > 1) {
    EXPECT_GE(owner_changes, 1);
    EXPECT_GT(most_held, 1);
  }
}

TEST(MpiSuspension, ChannelPeriodicAcrossTheSlabsEqualsTheSerialSuspension) {
  // A slit channel, periodic in y: the slabs wrap, and a cell pushed across y = +8 comes back at
  // -8 (its owner changes from the last rank to the first) while its stencils and repulsion reach
  // across the period.
  SuspensionOptions o;
  o.lattice.nx = 16;
  o.lattice.ny = 16;
  o.lattice.nz = 14;
  o.lattice.tau = 1.0;
  o.lattice.walls = false;
  o.lattice.collision = Collision::TRT;
  o.lattice.body_force = Vec3(5e-5, 0.0, 0.0);
  o.lattice.section = std::make_shared<SlabWall>(5.0);
  o.vessel = Vessel::channel(10.0, 16.0, 16.0);
  o.cell_contact = ContactLaw{0.02, 1.5};
  o.wall_contact = ContactLaw{0.02, 1.5};
  o.vertex_force = Vec3(0.0, 4e-4, 0.0);
  const auto m = small_rbc(3.0, 0.005);
  LbmSuspension serial(o);
  MpiSuspension d(o, MPI_COMM_WORLD);
  const Points& x = m->reference_positions();
  const Points a = moved(x, Vec3(-3.5, 7.95, 0.2)), b = moved(x, Vec3(3.5, -7.0, -0.3), 0.5);
  serial.add_cell(m, a);
  serial.add_cell(m, b);
  d.add_cell(m, a);
  d.add_cell(m, b);
  bool crossed = false;
  for (int step = 0; step < 40; ++step) {
    serial.step();
    d.step();
    crossed = crossed || serial.cell_positions(0).col(1).mean() < 0;
  }
  EXPECT_TRUE(crossed);  // the first cell went across the period
  EXPECT_EQ(d.gather_positions(), serial.positions());
  EXPECT_EQ(fluid_difference(d, serial), 0.0);
}

TEST(MpiSuspension, GatheredPositionsRestoreTheRun) {
  // A run restored from its gathered positions and its fluid (here the fluid's own state, as a
  // checkpoint would read it back) continues as the uninterrupted one.
  const auto m = small_rbc(3.5, 0.005);
  MpiSuspension a(tube_options(), MPI_COMM_WORLD);
  add_cells(a, m);
  a.run(20);
  const Points at20 = a.gather_positions();
  MpiSuspension b(tube_options(), MPI_COMM_WORLD);
  add_cells(b, m);
  b.fluid() = a.fluid();
  b.restore(at20);
  a.run(15);
  b.run(15);
  EXPECT_EQ(a.gather_positions(), b.gather_positions());
}

TEST(MpiSuspension, RefusesWhatTheSerialSuspensionRefuses) {
  SuspensionOptions o = tube_options();
  o.cell_contact.cutoff = 0;
  EXPECT_THROW(MpiSuspension(o, MPI_COMM_WORLD), Error);
  MpiSuspension d(tube_options(), MPI_COMM_WORLD);
  const auto m = small_rbc(3.5, 0.005);
  EXPECT_THROW(d.add_cell(m, Points::Zero(3, 3)), Error);
  EXPECT_THROW(d.add_cell(nullptr, m->reference_positions()), Error);
  EXPECT_THROW(d.restore(Points::Zero(3, 3)), Error);
}
