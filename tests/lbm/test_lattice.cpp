#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <omp.h>

#include "bendlab/flow/lbm/diagnostics.hpp"
#include "bendlab/flow/lbm/lattice.hpp"

using namespace bendlab;
using namespace bendlab::lbm;

namespace {

LatticeConfig box(int nx, int ny, int nz, double tau, bool walls, double v = 0.0) {
  LatticeConfig c;
  c.nx = nx;
  c.ny = ny;
  c.nz = nz;
  c.tau = tau;
  c.walls = walls;
  c.wall_velocity = v;
  return c;
}

// A smooth non-trivial state: density and velocity waves along all three axes.
void wavy_start(Lattice& L) {
  const double kx = 2 * std::numbers::pi / L.nx(), ky = 2 * std::numbers::pi / L.ny(), kz = 2 * std::numbers::pi / L.nz();
  L.initialise([&](const Vec3& x) { return Vec3(0.01 * std::sin(ky * x.y() + 0.3), 0.02 * std::cos(kz * x.z()), 0.015 * std::sin(kx * x.x() - 0.1)); },
               [&](const Vec3& x) { return 1.0 + 0.01 * std::cos(kx * x.x() + ky * x.y() + kz * x.z()); });
}

double max_abs_diff(const std::vector<double>& a, const std::vector<double>& b) {
  double m = 0;
  for (std::size_t i = 0; i < a.size(); ++i) m = std::max(m, std::abs(a[i] - b[i]));
  return m;
}

}  // namespace

TEST(Lattice, PeriodicBoxConservesMassAndMomentum) {
  for (double tau : {1.0, 0.8}) {
    Lattice L(box(7, 5, 6, tau, false));
    wavy_start(L);
    const double m0 = L.total_mass();
    const Vec3 p0 = L.total_momentum();
    L.run(41);  // odd: ends in the layout after an even step
    EXPECT_NEAR(L.total_mass(), m0, 1e-12 * m0) << "tau " << tau;
    EXPECT_LT((L.total_momentum() - p0).norm(), 1e-12 * m0) << "tau " << tau;
    // Guo forcing adds exactly the total force to the momentum each step (j* = j + F).
    for (std::size_t n = 0; n < L.num_nodes(); ++n) L.add_force(n, Vec3(1e-5 * (n % 3), -2e-6, 3e-6 * std::sin(n)));
    Vec3 Ftot = Vec3::Zero();
    for (std::size_t n = 0; n < L.num_nodes(); ++n) Ftot += L.force(n);
    const Vec3 p1 = L.total_momentum();
    L.run(10);
    EXPECT_NEAR(L.total_mass(), m0, 1e-12 * m0);
    EXPECT_LT((L.total_momentum() - p1 - 10.0 * Ftot).norm(), 1e-12 * m0) << "tau " << tau;
  }
}

TEST(Lattice, RegularizedEqualsBgkAtTauOne) {
  // ESPResSo's MRT at tau = 1 is BGK + Guo: both collisions give the same populations.
  LatticeConfig c = box(5, 4, 6, 1.0, true, 0.01);
  c.collision = Collision::BGK;
  Lattice a(c);
  c.collision = Collision::Regularized;
  Lattice b(c);
  for (Lattice* L : {&a, &b}) {
    wavy_start(*L);
    for (std::size_t n = 0; n < L->num_nodes(); ++n) L->add_force(n, Vec3(1e-4 * std::cos(n), 2e-4, -1e-4 * (n % 5)));
    L->run(5);
  }
  EXPECT_LT(max_abs_diff(a.raw_populations(), b.raw_populations()), 1e-15);
}

namespace {
// Max |u - gamma z e_x| and max |rho - 1| over the lattice.
std::pair<double, double> shear_flow_error(const Lattice& L) {
  double err = 0, drho = 0;
  for (std::size_t n = 0; n < L.num_nodes(); ++n) {
    const auto [i, j, k] = L.coordinates(n);
    err = std::max(err, (L.velocity(n) - Vec3(L.shear_rate() * L.position(i, j, k).z(), 0, 0)).norm());
    drho = std::max(drho, std::abs(L.density(n) - 1.0));
  }
  return {err, drho};
}
}  // namespace

TEST(Lattice, CouetteFlowFromRestConvergesToLinearProfile) {
  // The regularised scheme's Couette state departs from the linear profile at O(v^3) (see
  // RegularizedShearFlowErrorIsHigherOrderInWallSpeed); v = 1e-3 keeps that below 1e-11.
  for (double tau : {1.0, 0.8}) {
    const double v = tau == 1.0 ? 0.01 : 0.001;
    Lattice L(box(3, 2, 8, tau, true, v));
    // Slowest mode decays as exp(-pi^2 nu t / H^2); run to a factor e^-30.
    const double nu = L.viscosity();
    L.run(static_cast<std::int64_t>(30.0 * 64 / (std::numbers::pi * std::numbers::pi * nu)) | 1);
    EXPECT_LT(shear_flow_error(L).first, 1e-10) << "tau " << tau;
  }
}

TEST(Lattice, ExactShearFlowIsSteadyForBgk) {
  // With BGK, halfway bounce-back keeps the linear profile and its stress exactly, at any tau.
  for (double tau : {1.0, 0.7, 1.3}) {
    LatticeConfig c = box(4, 3, 16, tau, true, 0.02);
    c.collision = Collision::BGK;
    Lattice L(c);
    L.initialise_shear_flow();
    for (int s = 0; s < 2; ++s) {
      L.run(51);
      const auto [err, drho] = shear_flow_error(L);
      EXPECT_LT(err, 1e-14) << "tau " << tau;
      EXPECT_LT(drho, 1e-14) << "tau " << tau;
    }
  }
}

TEST(Lattice, RegularizedShearFlowErrorIsHigherOrderInWallSpeed) {
  // The regularised (MRT) collision drops the higher non-equilibrium moments that bounce-back
  // creates at the walls, so for tau != 1 the Couette state carries an O(v^2) density and O(v^3)
  // velocity defect (a compressibility effect, far below the IB error at Ma < 0.01).
  std::pair<double, double> e[2];
  for (int s = 0; s < 2; ++s) {
    Lattice L(box(3, 2, 16, 0.8, true, s == 0 ? 0.01 : 0.02));
    L.initialise_shear_flow();
    L.run(3001);
    e[s] = shear_flow_error(L);
  }
  EXPECT_NEAR(e[1].first / e[0].first, 8.0, 0.4);
  EXPECT_NEAR(e[1].second / e[0].second, 4.0, 0.2);
  EXPECT_LT(e[0].first, 1e-3 * 0.01);
}

TEST(Lattice, PoiseuilleFlowConvergesAtSecondOrder) {
  for (double tau : {1.0, 0.8}) {
    std::vector<double> errors;
    for (int H : {8, 16, 32}) {
      Lattice L(box(1, 1, H, tau, true));
      const double nu = L.viscosity(), umax = 0.01, g = 8 * nu * umax / (H * H);
      auto exact = [&](double z) { return g / (2 * nu) * (0.25 * H * H - z * z); };
      L.set_uniform_force(Vec3(g, 0, 0));
      L.initialise([&](const Vec3& x) { return Vec3(exact(x.z()), 0, 0); });
      L.run(static_cast<std::int64_t>(12.0 * H * H / (std::numbers::pi * std::numbers::pi * nu)));
      double e2 = 0, u2 = 0;
      for (int k = 0; k < H; ++k) {
        const double z = L.position(0, 0, k).z(), u = L.velocity(L.index(0, 0, k)).x();
        e2 += (u - exact(z)) * (u - exact(z));
        u2 += exact(z) * exact(z);
      }
      errors.push_back(std::sqrt(e2 / u2));
    }
    for (std::size_t i = 0; i + 1 < errors.size(); ++i) {
      const double order = std::log2(errors[i] / errors[i + 1]);
      EXPECT_GT(order, 1.9) << "tau " << tau << " errors " << errors[i] << " " << errors[i + 1];
      EXPECT_LT(order, 2.1) << "tau " << tau;
    }
    EXPECT_LT(errors.back(), 1e-2);
  }
}

TEST(Lattice, ShearWaveDecaysWithLatticeViscosity) {
  for (double tau : {1.0, 0.8}) {
    const int N = 64;
    Lattice L(box(1, 1, N, tau, false));
    const double k = 2 * std::numbers::pi / N, A = 1e-4;
    L.initialise([&](const Vec3& x) { return Vec3(A * std::sin(k * x.z()), 0, 0); }, nullptr, [&](const Vec3& x) {
      Mat3 S = Mat3::Zero();
      S(2, 0) = A * k * std::cos(k * x.z());
      return S;
    });
    auto amplitude = [&] {
      double a = 0;
      for (int z = 0; z < N; ++z) a += L.velocity(L.index(0, 0, z)).x() * std::sin(k * L.position(0, 0, z).z());
      return 2.0 * a / N;
    };
    L.run(20);
    const double a0 = amplitude();
    const int T = 600;
    L.run(T);
    const double nu = -std::log(amplitude() / a0) / (k * k * T);
    EXPECT_NEAR(nu / L.viscosity(), 1.0, 1e-3) << "tau " << tau;
  }
}

TEST(Lattice, RejectsBadConfiguration) {
  EXPECT_THROW(Lattice(box(4, 4, 4, 0.5, true)), Error);
  EXPECT_THROW(Lattice(box(0, 4, 4, 1.0, true)), Error);
  EXPECT_THROW(Lattice(box(4, 4, 1, 1.0, true)), Error);
}

TEST(Diagnostics, FindsNonFiniteAndNegativeDensity) {
  Lattice L(box(4, 5, 6, 1.0, true, 0.01));
  L.initialise_shear_flow();
  L.run(3);
  EXPECT_FALSE(find_blow_up(L).has_value());
  const std::size_t node = L.index(1, 2, 3);
  for (double bad : {std::nan(""), -10.0, std::numeric_limits<double>::infinity()}) {
    std::vector<double> f = L.raw_populations();
    f[node] = bad;  // slot 0 (rest population) of the node, in either layout
    Lattice M(L.config());
    M.restore_raw(f, L.step_count());
    const auto b = find_blow_up(M);
    ASSERT_TRUE(b.has_value());
    EXPECT_EQ(b->node, node);
    EXPECT_EQ(b->ijk, (std::array<int, 3>{1, 2, 3}));
    EXPECT_EQ(b->step, 3);
    EXPECT_NE(b->message.find("step 3"), std::string::npos) << b->message;
    EXPECT_NE(b->message.find("(1, 2, 3)"), std::string::npos) << b->message;
  }
}

TEST(Lattice, ThreadedStepMatchesSerialStep) {
  // 32^3 nodes: large enough for the OpenMP path; each node's update does not depend on the
  // thread count, so the populations agree bit for bit.
  std::vector<double> result[2];
  for (int t = 0; t < 2; ++t) {
    omp_set_num_threads(t + 1);
    Lattice L(box(32, 32, 32, 0.9, true, 0.01));
    wavy_start(L);
    for (std::size_t n = 0; n < L.num_nodes(); n += 7) L.add_force(n, Vec3(1e-4, -1e-4, 2e-4));
    L.run(3);
    result[t] = L.raw_populations();
  }
  EXPECT_EQ(result[0], result[1]);
}

TEST(Lattice, PaddedSlotsMatchThePlainLayout) {
  // The padded store (slot_stride() > num_nodes()) changes where the populations live, not what
  // they are: after steps of both parities, with walls, a force field and both collisions, the
  // populations agree bit for bit with the plain layout's.
  for (const double tau : {1.0, 0.9}) {
    std::vector<double> result[2];
    std::size_t stride[2];
    for (int pad = 0; pad < 2; ++pad) {
      LatticeConfig c = box(12, 10, 8, tau, true, 0.01);
      c.pad_slots = pad == 1;
      Lattice L(c);
      stride[pad] = L.slot_stride();
      wavy_start(L);
      for (std::size_t n = 0; n < L.num_nodes(); n += 5) L.add_force(n, Vec3(1e-4, -1e-4, 2e-4));
      L.run(5);
      EXPECT_EQ(L.force(5), Vec3(1e-4, -1e-4, 2e-4));
      result[pad] = L.raw_populations();
    }
    EXPECT_EQ(stride[0], 12u * 10u * 8u);
    EXPECT_GT(stride[1], stride[0]);
    EXPECT_EQ(result[0], result[1]) << "tau " << tau;
  }
}

TEST(Lattice, ClearForceZeroesEveryNodeWritten) {
  // clear_force zeroes only the nodes written since the last clear while they are few, and the
  // whole field once they are many or after set_uniform_force: each way leaves no force behind.
  Lattice L(box(8, 6, 5, 1.0, true, 0.01));
  const auto all_zero = [&] {
    for (std::size_t n = 0; n < L.num_nodes(); ++n)
      if (L.force(n) != Vec3::Zero()) return false;
    return true;
  };
  L.add_force(3, Vec3(1, 2, 3));
  L.add_force(3, Vec3(1, 0, 0));
  L.add_force(L.num_nodes() - 1, Vec3(0, 0, -1));
  EXPECT_EQ(L.force(3), Vec3(2, 2, 3));
  L.clear_force();
  EXPECT_TRUE(all_zero());
  for (std::size_t n = 0; n < L.num_nodes(); n += 2) L.add_force(n, Vec3(1e-3, 0, 0));  // more than n / 8
  L.clear_force();
  EXPECT_TRUE(all_zero());
  L.set_uniform_force(Vec3(0, 1e-4, 0));
  L.add_force(7, Vec3(1, 1, 1));
  L.clear_force();
  EXPECT_TRUE(all_zero());
}

// The immersed boundary's gather, velocities_of_run, against velocity() node by node, bit for bit:
// whole rows and runs that start and end inside a row (which wrap along x at odd steps), at both
// parities, on a periodic box, moving walls and a tube's section (whose solid rows give zero).
TEST(Lattice, VelocitiesOfARunEqualVelocityAtEveryNode) {
  std::vector<LatticeConfig> configs;
  configs.push_back(box(5, 4, 6, 0.9, false));
  configs.push_back(box(70, 3, 4, 1.0, true, 0.02));  // rows longer than one chunk of the run
  LatticeConfig tube = box(6, 12, 12, 1.2, false);
  tube.collision = Collision::TRT;
  tube.section = std::make_shared<TubeWall>(4.3);
  configs.push_back(tube);
  for (const LatticeConfig& c : configs) {
    Lattice L(c);
    L.initialise([](const Vec3& x) { return Vec3(0.01 * std::cos(x.z()), 0.003 * std::sin(x.x()), 0.002 * x.y()); });
    L.set_uniform_force(Vec3(1e-5, -2e-5, 3e-6));
    L.add_force(1, Vec3(2e-4, 1e-4, -3e-4));
    const int nx = L.nx();
    for (int step = 0; step < 3; ++step) {
      for (std::size_t row = 0; row < L.num_nodes() / static_cast<std::size_t>(nx); ++row) {
        for (const auto& [from, count] : {std::pair{0, nx}, std::pair{1, nx - 2}, std::pair{nx - 1, 1}}) {
          const std::size_t first = row * static_cast<std::size_t>(nx) + static_cast<std::size_t>(from);
          std::vector<double> u(3 * static_cast<std::size_t>(count));
          L.velocities_of_run(first, count, u.data());
          for (int t = 0; t < count; ++t) {
            const Vec3 v = L.velocity(first + static_cast<std::size_t>(t));
            for (int d = 0; d < 3; ++d) ASSERT_EQ(u[3 * static_cast<std::size_t>(t) + static_cast<std::size_t>(d)], v[d]) << "step " << step << " node " << first + static_cast<std::size_t>(t);
          }
        }
      }
      L.step();
    }
    std::vector<double> u(3 * static_cast<std::size_t>(nx));
    EXPECT_THROW(L.velocities_of_run(1, nx, u.data()), Error);  // leaves the row
  }
}

// A writer that declares its runs (the immersed boundary's spreading) leaves a field that
// clear_force clears entirely: runs alone, runs beside add_force, and runs that cover more than
// half of the field (then swept whole).
TEST(Lattice, ClearForceClearsTheRunsWrittenThrough) {
  Lattice L(box(10, 6, 5, 1.0, false));
  const std::size_t n = L.num_nodes(), S = L.slot_stride();
  auto all_zero = [&] {
    for (int d = 0; d < 3; ++d)
      for (std::size_t node = 0; node < n; ++node)
        if (L.force_data(d)[node] != 0.0) return false;
    return true;
  };
  for (const std::size_t rows : {std::size_t{3}, std::size_t{25}}) {  // 30 and 250 of 300 nodes
    std::vector<Lattice::NodeRun> runs;
    for (std::size_t r = 0; r < rows; ++r) runs.push_back({10 * r + 2, 7});
    double* f = L.force_field_for_writing(runs);
    for (const Lattice::NodeRun& run : runs)
      for (int t = 0; t < run.count; ++t)
        for (int d = 0; d < 3; ++d) f[d * S + run.first + static_cast<std::size_t>(t)] = 1.0 + d;
    L.add_force(n - 1, Vec3(1, 2, 3));
    EXPECT_FALSE(all_zero());
    L.clear_force();
    EXPECT_TRUE(all_zero()) << rows << " rows written";
  }
}

// step_gathering against step() then velocities_of_run, bit for bit: the same populations, and the
// same velocities for the runs the step gathered and for those it left (rows beside a wall link,
// rows whose neighbours another thread steps), at both parities, on 1, 2 and 3 threads, on lattices
// large enough to step on all of them: a periodic box (rows that wrap in y and z), moving walls,
// a tube's section and a slit's.
TEST(Lattice, StepGatheringEqualsTheStepThenTheGather) {
  std::vector<LatticeConfig> configs;
  configs.push_back(box(16, 16, 17, 0.9, false));
  configs.push_back(box(16, 17, 16, 1.0, true, 0.02));
  LatticeConfig tube = box(16, 20, 20, 1.2, false);
  tube.collision = Collision::TRT;
  tube.section = std::make_shared<TubeWall>(8.3);
  configs.push_back(tube);
  LatticeConfig slit = box(16, 18, 16, 0.8, false);
  slit.collision = Collision::TRT;
  slit.section = std::make_shared<SlabWall>(6.0);
  configs.push_back(slit);
  const int threads_before = omp_get_max_threads();
  for (const LatticeConfig& c : configs) {
    for (int threads = 1; threads <= 3; ++threads) {
      omp_set_num_threads(threads);
      Lattice A(c), B(c);
      for (Lattice* L : {&A, &B}) {
        L->initialise([](const Vec3& x) { return Vec3(0.01 * std::cos(x.z()), 0.003 * std::sin(x.x()), 0.002 * x.y()); });
        L->set_uniform_force(Vec3(1e-5, -2e-5, 3e-6));
        L->add_force(1, Vec3(2e-4, 1e-4, -3e-4));
      }
      ASSERT_GE(A.num_nodes(), std::size_t{4096}) << "the lattice must step on every thread";
      const int nx = A.nx();
      // Two runs per row, ascending: the row's first three nodes and its last nx - 5.
      std::vector<Lattice::NodeRun> runs;
      for (std::size_t row = 0; row < A.num_nodes() / static_cast<std::size_t>(nx); ++row) {
        runs.push_back({row * static_cast<std::size_t>(nx), 3});
        runs.push_back({row * static_cast<std::size_t>(nx) + 5, nx - 5});
      }
      std::size_t gathered = 0, left = 0;
      for (int step = 0; step < 4; ++step) {
        std::vector<double> u(3 * A.num_nodes(), std::numeric_limits<double>::quiet_NaN());
        std::vector<std::uint8_t> done;
        A.step_gathering(runs, u.data(), done);
        B.step();
        ASSERT_EQ(A.raw_populations(), B.raw_populations()) << "step " << step << ", " << threads << " threads";
        ASSERT_EQ(done.size(), runs.size());
        for (std::size_t k = 0; k < runs.size(); ++k) {
          std::vector<double> want(3 * static_cast<std::size_t>(runs[k].count)), left_for_later(want.size());
          B.velocities_of_run(runs[k].first, runs[k].count, want.data());
          A.velocities_of_run(runs[k].first, runs[k].count, left_for_later.data());
          const double* got = done[k] ? u.data() + 3 * runs[k].first : left_for_later.data();
          (done[k] ? gathered : left) += 1;
          for (std::size_t i = 0; i < want.size(); ++i)
            ASSERT_EQ(got[i], want[i]) << "step " << step << ", " << threads << " threads, run " << k << (done[k] ? " gathered" : " left") << " i " << i;
        }
      }
      EXPECT_GT(gathered, 0u) << "the step gathered no run";
      if (c.section != nullptr || threads > 1) {
        EXPECT_GT(left, 0u) << "the step left no run (wall links, thread borders)";
      }
    }
  }
  omp_set_num_threads(threads_before);
}

// The row table of populations() against the coordinates of populations_reference(), every node
// at both parities, on every kind of lattice: fully periodic, moving walls, a tube's section and a
// slit's, with a flow and a force so that no population is trivially equal to another.
TEST(Lattice, PopulationsEqualTheReferenceAtEveryNode) {
  std::vector<LatticeConfig> configs;
  configs.push_back(box(5, 4, 6, 0.9, false));
  configs.push_back(box(5, 4, 6, 1.0, true, 0.02));
  LatticeConfig tube = box(4, 12, 12, 1.2, false);
  tube.collision = Collision::TRT;
  tube.section = std::make_shared<TubeWall>(4.3);
  configs.push_back(tube);
  LatticeConfig slit = box(4, 5, 12, 0.8, false);
  slit.collision = Collision::TRT;
  slit.section = std::make_shared<SlabWall>(4.0);
  configs.push_back(slit);
  for (const LatticeConfig& c : configs) {
    Lattice L(c);
    L.initialise([](const Vec3& x) { return Vec3(0.01 * std::cos(x.z()), 0.003 * std::sin(x.x()), 0.002 * x.y()); });
    L.set_uniform_force(Vec3(1e-5, -2e-5, 3e-6));
    for (int step = 0; step < 3; ++step) {
      for (std::size_t node = 0; node < L.num_nodes(); ++node) {
        double fast[kQ], reference[kQ];
        L.populations(node, fast);
        L.populations_reference(node, reference);
        for (int q = 0; q < kQ; ++q) ASSERT_EQ(fast[q], reference[q]) << "step " << L.step_count() << " node " << node << " q " << q;
      }
      L.step();
    }
  }
}
