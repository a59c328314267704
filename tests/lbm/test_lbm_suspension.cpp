// Many cells in one lattice Boltzmann fluid (lbm_suspension.hpp): cells that meet in shear and a
// cell pushed onto a wall never overlap or cross it (checked with the winding number on every
// vertex, not with distances between centroids), total momentum follows the external forces
// exactly, and a cell leaving the box comes back whole by one period.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include <omp.h>

#include "bendlab/flow/lbm/lbm_suspension.hpp"
#include "bendlab/flow/lbm/section_walls.hpp"
#include "bendlab/geometry/measures.hpp"
#include "bendlab/geometry/point_in_mesh.hpp"
#include "lbm/suspension_cells.hpp"

using namespace bendlab;
using namespace bendlab::lbm;

namespace {

using test::moved;

std::shared_ptr<const MembraneModel> rbc(double R, double kS) { return test::small_rbc(R, kS); }

// Whether any vertex of cell a lies inside cell b (b at its nearest image to a along x).
bool any_vertex_inside(const LbmSuspension& s, int a, int b) {
  Points xb = s.cell_positions(b);
  const Points xa = s.cell_positions(a);
  const double L = s.options().vessel.length();
  const double dx = xa.col(0).mean() - xb.col(0).mean();
  xb.col(0).array() += L * std::round(dx / L);
  const BoundingBox box = bounding_box(xb);
  for (Eigen::Index i = 0; i < xa.rows(); ++i) {
    if (contains(s.membrane(b).topology(), xb, box, row(xa, i))) return true;
  }
  return false;
}

}  // namespace

// Two cells on either side of the mid-plane of a shear box, carried towards each other by the
// flow: they must pass without a vertex ever entering the other cell.
TEST(LbmSuspension, CellsMeetingInShearNeverOverlap) {
  SuspensionOptions o;
  o.lattice.nx = 32;
  o.lattice.ny = 14;
  o.lattice.nz = 16;
  o.lattice.tau = 1.0;
  o.lattice.walls = true;
  o.lattice.wall_velocity = 0.05;
  o.vessel = Vessel::box(16, 14, 32);
  o.cell_contact = ContactLaw{0.02, 1.5};  // the immersed boundary alone keeps these cells 1.4 dx apart
  LbmSuspension s(o);
  s.lattice().initialise_shear_flow();
  const auto m = rbc(4.0, 0.005);
  // The upper cell starts upstream (u = gamma z e_x); both discs stand nearly edge-on to the flow,
  // their z ranges overlapping by 6 dx, so the cells collide instead of sliding past.
  s.add_cell(m, moved(m->reference_positions(), Vec3(-3.5, 0, 1.0), 1.4));
  s.add_cell(m, moved(m->reference_positions(), Vec3(3.5, 0, -1.0), -1.4));
  double most_contact = 0;
  for (int step = 1; step <= 600; ++step) {  // in contact from about step 400
    s.step();
    most_contact = std::max(most_contact, s.cell_contact_energy());
    if (step % 25 != 0) continue;
    ASSERT_FALSE(any_vertex_inside(s, 0, 1)) << "step " << s.steps();
    ASSERT_FALSE(any_vertex_inside(s, 1, 0)) << "step " << s.steps();
  }
  // The test means something only if the cells came within the contact's reach.
  EXPECT_GT(most_contact, 0.0) << "the cells never met";
}

// A cell pushed towards the bottom wall of a channel by a force on every vertex (sedimentation):
// it comes to rest on the wall's repulsion, and no vertex ever crosses the wall.
TEST(LbmSuspension, CellPressedOntoAWallNeverCrossesIt) {
  SuspensionOptions o;
  o.lattice.nx = 20;
  o.lattice.ny = 20;
  o.lattice.nz = 16 + 4;
  o.lattice.tau = 1.0;
  o.lattice.walls = false;
  o.lattice.collision = Collision::TRT;
  o.lattice.section = std::make_shared<SlabWall>(8.0);
  o.vessel = Vessel::channel(16, 20, 20);
  o.wall_contact = ContactLaw{0.05, 1.0};
  o.vertex_force = Vec3(0, 0, -1e-3);
  LbmSuspension s(o);
  const auto m = rbc(4.0, 0.01);
  s.add_cell(m, moved(m->reference_positions(), Vec3(0, 0, -5.8)));
  double nearest = 1e9;
  for (int check = 0; check < 30; ++check) {
    s.run(20);
    for (Eigen::Index k = 0; k < s.positions().rows(); ++k) {
      const double d = s.options().vessel.wall_distance(row(s.positions(), k));
      ASSERT_GT(d, 0.0) << "vertex " << k << " crossed the wall at step " << s.steps();
      nearest = std::min(nearest, d);
    }
  }
  EXPECT_LT(nearest, 1.0) << "the cell never reached the wall's contact zone";
  EXPECT_GT(s.wall_contact_energy(), 0.0);
}

// In a periodic box without walls the membrane, volume and contact forces are internal: the
// fluid's momentum (with the cells, one fluid for the immersed boundary) grows each step by the
// body force on every node plus the external force on every vertex, exactly.
TEST(LbmSuspension, MomentumGrowsByTheExternalForcesOnly) {
  SuspensionOptions o;
  o.lattice.nx = 24;
  o.lattice.ny = 14;
  o.lattice.nz = 14;
  o.lattice.walls = false;
  o.lattice.collision = Collision::TRT;
  o.lattice.tau = 0.9;
  o.lattice.body_force = Vec3(1e-6, 0, 0);
  o.vessel = Vessel::box(1e9, 14, 24);  // no wall within reach
  o.cell_contact = ContactLaw{0.01, 1.5};
  o.vertex_force = Vec3(0, 3e-7, 0);
  LbmSuspension s(o);
  const auto m = rbc(3.5, 0.005);
  s.add_cell(m, moved(m->reference_positions() * 1.05, Vec3(-5, 0, 0), 0.3));  // stretched: elastic forces act
  s.add_cell(m, moved(m->reference_positions(), Vec3(2.6, 0.5, 0), 1.2));
  s.run(3);
  // Momentum of the populations plus the half force (the velocity's definition).
  auto momentum = [&]() {
    Vec3 p = Vec3::Zero();
    for (std::size_t n = 0; n < s.lattice().num_nodes(); ++n) p += s.lattice().velocity(n) * s.lattice().density(n);
    return p;
  };
  const Vec3 p0 = s.lattice().total_momentum();
  const int steps = 20;
  s.run(steps);
  const Vec3 p1 = s.lattice().total_momentum();
  const double nodes = static_cast<double>(s.lattice().num_nodes()), vertices = static_cast<double>(s.positions().rows());
  const Vec3 expected = steps * (o.lattice.body_force * nodes + o.vertex_force * vertices);
  EXPECT_LT((p1 - p0 - expected).norm(), 1e-10 * expected.norm()) << (p1 - p0).transpose() << " vs " << expected.transpose();
  (void)momentum;
}

// A cell carried past x = L/2 comes back by one period, whole: its shape is the same up to the
// shift, and its vertex mean stays in the box.
TEST(LbmSuspension, CellLeavingTheBoxComesBackWhole) {
  SuspensionOptions o;
  o.lattice.nx = 16;
  o.lattice.ny = 14;
  o.lattice.nz = 14;
  o.lattice.walls = false;
  o.lattice.collision = Collision::TRT;
  o.lattice.tau = 1.0;
  o.vessel = Vessel::box(1e9, 14, 16);
  LbmSuspension s(o);
  s.lattice().initialise([](const Vec3&) { return Vec3(0.02, 0, 0); });
  const auto m = rbc(3.0, 0.005);
  s.add_cell(m, moved(m->reference_positions(), Vec3(7.0, 0, 0)));
  const double xc0 = s.positions().col(0).mean();
  s.run(60);  // carried about 1.2 dx: its mean passes x = 8
  const double xc1 = s.positions().col(0).mean();
  EXPECT_LT(xc1, 0.0);                          // wrapped to the left half
  EXPECT_NEAR(xc1 + 16 - xc0, 1.2, 0.1);        // moved by the flow's 0.02 per step, up to the period
  const Points x = s.cell_positions(0);
  EXPECT_LT(x.col(0).maxCoeff() - x.col(0).minCoeff(), 6.5);  // its vertices together, not split
}

// The cells' forces on one or two threads, and the immersed boundary's: the same positions bit for
// bit (each cell's forces are its own; the stencil sums keep their order).
TEST(LbmSuspension, ThreadCountDoesNotChangeTheRun) {
  auto run = [](int threads) {
    const int saved = omp_get_max_threads();
    omp_set_num_threads(threads);
    SuspensionOptions o;
    o.lattice.nx = 24;
    o.lattice.ny = 14;
    o.lattice.nz = 16;
    o.lattice.walls = true;
    o.lattice.wall_velocity = 0.05;
    o.vessel = Vessel::box(16, 14, 24);
    o.cell_contact = ContactLaw{0.02, 1.5};
    LbmSuspension s(o);
    s.lattice().initialise_shear_flow();
    const auto m = rbc(3.5, 0.005);
    s.add_cell(m, moved(m->reference_positions(), Vec3(-3.0, 0, 1.0), 1.4));
    s.add_cell(m, moved(m->reference_positions(), Vec3(3.0, 0, -1.0), -1.4));
    s.add_cell(m, moved(m->reference_positions(), Vec3(9.0, 0, 3.5), 0.3));
    s.run(40);
    omp_set_num_threads(saved);
    return Points(s.positions());
  };
  const Points one = run(1), two = run(2);
  EXPECT_EQ(one, two);
}

// --membrane-every N: the membrane forces of steps 1 .. N are those of the positions before step 1,
// those of steps N + 1 .. 2N those before step N + 1, bit for bit; N = 1 is the suspension of
// every step. A suspension restored at a step the forces are renewed repeats the uninterrupted run.
TEST(LbmSuspension, MembraneForcesEveryNStepsAreHeldFromTheStepThatRenewedThem) {
  auto make = [](int every) {
    SuspensionOptions o;
    o.lattice.nx = 20;
    o.lattice.ny = 14;
    o.lattice.nz = 14;
    o.lattice.walls = false;
    o.lattice.collision = Collision::TRT;
    o.lattice.tau = 0.9;
    o.vessel = Vessel::box(1e9, 14, 20);
    o.membrane_every = every;
    auto s = std::make_unique<LbmSuspension>(o);
    s->lattice().initialise([](const Vec3& x) { return Vec3(0.01 * std::sin(0.3 * x.z()), 0, 0.005); });
    const auto m = rbc(3.5, 0.005);
    s->add_cell(m, moved(m->reference_positions() * 1.05, Vec3(0, 0, 0), 0.3));  // stretched: elastic forces act
    return s;
  };
  auto membrane_forces = [](const LbmSuspension& s) {
    Points f;
    s.membrane(0).forces(s.cell_positions(0), f);
    return f;
  };
  const int N = 3;
  auto held = make(N), every = make(1);
  EXPECT_THROW(make(0), Error);
  Points renewed = membrane_forces(*held);
  for (int step = 1; step <= 3 * N; ++step) {
    if ((step - 1) % N == 0) renewed = membrane_forces(*held);
    const Points expected_every = membrane_forces(*every);
    held->step();
    every->step();
    ASSERT_EQ(held->forces(), renewed) << "step " << step;
    ASSERT_EQ(every->forces(), expected_every) << "step " << step;
  }
  EXPECT_GT((held->positions() - every->positions()).cwiseAbs().maxCoeff(), 0.0);  // holding changes the run
  // Restored after 2N steps into a fresh suspension: the same as running on.
  auto resumed = make(N);
  resumed->restore(held->lattice(), held->positions());
  held->run(N + 1);
  resumed->run(N + 1);
  EXPECT_EQ(resumed->positions(), held->positions());
}

// The shear box's moving walls repel as a channel's resting ones do: a cell pushed towards the top
// wall comes to rest on the repulsion, no vertex crosses the wall, and the immersed boundary's
// kernel never reaches it (which the lattice would refuse).
TEST(LbmSuspension, CellPressedOntoAMovingWallNeverCrossesIt) {
  SuspensionOptions o;
  o.lattice.nx = 24;
  o.lattice.ny = 16;
  o.lattice.nz = 18;
  o.lattice.tau = 1.0;
  o.lattice.walls = true;
  o.lattice.wall_velocity = 0.02;
  o.vessel = Vessel::box(18, 16, 24);
  o.wall_contact = ContactLaw{0.05, 2.0};
  o.vertex_force = Vec3(0, 0, 1e-3);
  LbmSuspension s(o);
  s.lattice().initialise_shear_flow();
  const auto m = rbc(4.0, 0.01);
  s.add_cell(m, moved(m->reference_positions(), Vec3(0, 0, 5.0)));
  double nearest = 1e9;
  for (int check = 0; check < 30; ++check) {
    ASSERT_NO_THROW(s.run(20)) << "step " << s.steps();
    for (Eigen::Index k = 0; k < s.positions().rows(); ++k) {
      const double d = s.options().vessel.wall_distance(row(s.positions(), k));
      ASSERT_GT(d, 1.0) << "vertex " << k << " within the kernel's reach of the wall at step " << s.steps();
      nearest = std::min(nearest, d);
    }
  }
  EXPECT_LT(nearest, 2.0) << "the cell never reached the wall's contact zone";
  EXPECT_GT(s.wall_contact_energy(), 0.0);
}
