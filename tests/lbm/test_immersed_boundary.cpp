#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <random>

#include <omp.h>

#include "bendlab/flow/lbm/immersed_boundary.hpp"
#include "bendlab/flow/lbm/section_walls.hpp"

using namespace bendlab;
using namespace bendlab::lbm;

namespace {

const IbKernel kKernels[] = {IbKernel::Phi2, IbKernel::Phi3, IbKernel::Phi4};

LatticeConfig walled(int nx, int ny, int nz, double v = 0.0) {
  LatticeConfig c;
  c.nx = nx;
  c.ny = ny;
  c.nz = nz;
  c.wall_velocity = v;
  return c;
}

// Random positions at least 3 dx inside every face of the box, where no stencil wraps.
Points random_points(const Lattice& L, int n, std::mt19937& rng) {
  Points X(n, 3);
  for (int d = 0; d < 3; ++d) {
    const int len = d == 0 ? L.nx() : (d == 1 ? L.ny() : L.nz());
    std::uniform_real_distribution<double> u(-0.5 * len + 3, 0.5 * len - 3);
    for (int k = 0; k < n; ++k) X(k, d) = u(rng);
  }
  return X;
}

Vec3 node_position(const Lattice& L, std::size_t node) {
  const auto [i, j, k] = L.coordinates(node);
  return L.position(i, j, k);
}

}  // namespace

TEST(ImmersedBoundary, KernelsSumToOneWithZeroFirstMoment) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-3.0, 3.0);
  for (IbKernel kernel : kKernels) {
    for (int t = 0; t < 200; ++t) {
      const double r = u(rng);
      double s0 = 0, s1 = 0;
      for (int i = -6; i <= 6; ++i) {
        s0 += ib_kernel(kernel, r - i);
        s1 += (r - i) * ib_kernel(kernel, r - i);
      }
      EXPECT_NEAR(s0, 1.0, 1e-14);
      EXPECT_NEAR(s1, 0.0, 1e-14);
    }
    EXPECT_EQ(ib_kernel(kernel, ib_kernel_half_width(kernel) + 1e-12), 0.0);
  }
}

TEST(ImmersedBoundary, StencilWeightsSumToOneAndReproduceLinearFields) {
  Lattice L(walled(16, 14, 20));
  std::mt19937 rng(11);
  const Points X = random_points(L, 100, rng);
  for (IbKernel kernel : kKernels) {
    for (int k = 0; k < X.rows(); ++k) {
      const IbStencil st = ib_stencil(L, row(X, k), kernel);
      double s0 = 0;
      Vec3 s1 = Vec3::Zero();
      for (int s = 0; s < st.size; ++s) {
        s0 += st.weight[s];
        s1 += st.weight[s] * node_position(L, st.node[s]);
      }
      EXPECT_NEAR(s0, 1.0, 1e-14);
      EXPECT_LT((s1 - row(X, k)).norm(), 1e-13);
    }
  }
}

TEST(ImmersedBoundary, InterpolatesLinearVelocityExactly) {
  Lattice L(walled(16, 14, 20));
  const Vec3 a(0.01, -0.02, 0.005);
  Mat3 B;
  B << 1e-3, 2e-4, -5e-4, 3e-4, -1e-3, 2e-4, 1e-4, 4e-4, 6e-4;
  auto u = [&](const Vec3& x) -> Vec3 { return a + B * x; };
  L.initialise(u);
  L.run(1);  // read through the odd-parity layout as well
  L.initialise(u);
  std::mt19937 rng(3);
  const Points X = random_points(L, 50, rng);
  for (IbKernel kernel : kKernels) {
    Points U;
    interpolate_velocity(L, X, U, kernel);
    for (int k = 0; k < X.rows(); ++k) EXPECT_LT((row(U, k) - u(row(X, k))).norm(), 1e-15);
  }
}

TEST(ImmersedBoundary, SpreadingConservesForceAndTorque) {
  std::mt19937 rng(5);
  std::normal_distribution<double> n01;
  for (IbKernel kernel : kKernels) {
    Lattice L(walled(16, 16, 18));
    const Points X = random_points(L, 40, rng);
    Points F(X.rows(), 3);
    for (int k = 0; k < F.rows(); ++k) F.row(k) = Vec3(n01(rng), n01(rng), n01(rng)).transpose();
    spread_forces(L, X, F, kernel);
    Vec3 f_nodes = Vec3::Zero(), t_nodes = Vec3::Zero(), f_markers = Vec3::Zero(), t_markers = Vec3::Zero();
    for (std::size_t n = 0; n < L.num_nodes(); ++n) {
      f_nodes += L.force(n);
      t_nodes += node_position(L, n).cross(L.force(n));
    }
    for (int k = 0; k < X.rows(); ++k) {
      f_markers += row(F, k);
      t_markers += row(X, k).cross(row(F, k));
    }
    EXPECT_LT((f_nodes - f_markers).norm(), 1e-12);
    EXPECT_LT((t_nodes - t_markers).norm(), 1e-11);
  }
}

TEST(ImmersedBoundary, PeriodicSupportWrapsInXAndY) {
  Lattice L(walled(8, 6, 12));
  const Points X = (Points(1, 3) << 3.9, -2.8, 0.3).finished();  // support crosses x and y faces
  const Points F = (Points(1, 3) << 1.0, 2.0, 3.0).finished();
  for (IbKernel kernel : kKernels) {
    L.clear_force();
    spread_forces(L, X, F, kernel);
    Vec3 total = Vec3::Zero();
    for (std::size_t n = 0; n < L.num_nodes(); ++n) total += L.force(n);
    EXPECT_LT((total - row(F, 0)).norm(), 1e-14);
    EXPECT_GT(L.force(L.index(0, 0, 6)).norm(), 0.0);  // wrapped across both faces
  }
}

TEST(ImmersedBoundary, SupportAcrossAWallIsAnError) {
  Lattice L(walled(8, 8, 10));
  // The outermost nodes sit at z = -+4.5; phi2 at z = 4.5 only touches them.
  EXPECT_NO_THROW(ib_stencil(L, Vec3(0, 0, 4.5), IbKernel::Phi2));
  EXPECT_THROW(ib_stencil(L, Vec3(0, 0, 4.6), IbKernel::Phi2), Error);
  EXPECT_THROW(ib_stencil(L, Vec3(0, 0, -4.0), IbKernel::Phi4), Error);
  EXPECT_THROW(ib_stencil(L, Vec3(0, NAN, 0), IbKernel::Phi2), Error);
}

TEST(ImmersedBoundary, ForceFreeNodesAreAdvectedByTheShearFlow) {
  Lattice L(walled(8, 8, 16, 0.02));
  L.initialise_shear_flow();
  Points X = (Points(3, 3) << 0.2, 0.1, -3.3, -1.0, 2.0, 0.7, 3.0, -3.5, 5.2).finished();
  const Points X0 = X, F = Points::Zero(3, 3);
  Points U;
  for (int s = 0; s < 3; ++s) ib_step(L, X, F, U);
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(X(k, 0), X0(k, 0) + 3 * L.shear_rate() * X0(k, 2), 1e-14);
    EXPECT_EQ(X(k, 1), X0(k, 1));
    EXPECT_NEAR(X(k, 2), X0(k, 2), 1e-15);
  }
}

TEST(ImmersedBoundary, VelocityIncludesHalfTheSpreadForce) {
  // A force spread onto fluid at rest shows as F/(2 rho) in the velocity before any step.
  Lattice L(walled(8, 8, 8));
  const Points X = (Points(1, 3) << 0.0, 0.0, 0.0).finished();
  const Points F = (Points(1, 3) << 0.8, 0.0, 0.0).finished();
  spread_forces(L, X, F);
  Points U;
  interpolate_velocity(L, X, U);
  // X sits at the centre of 8 nodes, each with weight 1/8: U = sum w (w F / 2) = F / 16.
  EXPECT_NEAR(U(0, 0), 0.8 / 16, 1e-15);
}

// The shared-node interpolator against the plain one: the same sums in the same order, so the
// same bits, on overlapping stencils, across steps (its cache must not outlive a step) and with
// a tube's solid nodes in reach.
// The step with the gather folded in (Lattice::step_gathering) against the step, then the
// interpolation: the same U and populations bit for bit, on 1, 2 and 3 threads, with nodes on the
// axis, near the tube's wall (whose rows wait for the wall pass) and spread across the tube.
TEST(ImmersedBoundary, StepAndInterpolateEqualsTheStepThenTheInterpolation) {
  LatticeConfig c;
  c.nx = 24, c.ny = c.nz = 16, c.tau = 0.9, c.walls = false, c.collision = Collision::TRT;
  c.body_force = Vec3(2e-5, 0, 0);
  c.section = std::make_shared<TubeWall>(6.5);
  Lattice L(c);
  ASSERT_GE(L.num_nodes(), std::size_t{4096});  // steps on every thread
  L.initialise([](const Vec3& x) { return Vec3(0.01 * (40 - x.y() * x.y() - x.z() * x.z()) / 40, 0.002 * std::sin(x.x()), 0.0); });
  Points X(300, 3), F(300, 3);
  for (Eigen::Index k = 0; k < X.rows(); ++k) {
    const double t = 0.37 * k, r = 5.4 * (0.5 + 0.5 * std::sin(0.05 * k));
    X.row(k) << 11.0 * std::sin(0.11 * k), r * std::cos(t), r * std::sin(t);
    F.row(k) << 1e-4 * std::sin(0.3 * k), 2e-5 * std::cos(0.2 * k), -3e-5;
  }
  const int saved = omp_get_max_threads();
  for (int threads : {1, 2, 3}) {
    omp_set_num_threads(threads);
    Lattice a = L, b = L;
    IbInterpolator ia, ib;
    for (int step = 0; step < 4; ++step) {  // both parities of the layout
      Points Ua, Ub;
      for (auto [lattice, ip] : {std::pair{&a, &ia}, std::pair{&b, &ib}}) {
        lattice->clear_force();
        ip->prepare(*lattice, X);
        ip->spread(*lattice, F);
      }
      a.step();
      ia.interpolate(a, Ua);
      ib.step_and_interpolate(b, Ub);
      ASSERT_EQ(a.raw_populations(), b.raw_populations()) << "step " << step << ", " << threads << " threads";
      ASSERT_EQ(Ua, Ub) << "step " << step << ", " << threads << " threads";
      X += Ua;
    }
  }
  omp_set_num_threads(saved);
}

TEST(ImmersedBoundary, SharedNodeInterpolatorEqualsThePlainOne) {  // and its spreading, spread_forces
  LatticeConfig c;
  c.nx = 12, c.ny = c.nz = 14, c.tau = 0.9, c.walls = false, c.collision = Collision::TRT;
  c.body_force = Vec3(2e-5, 0, 0);
  c.section = std::make_shared<TubeWall>(5.5);
  Lattice L(c);
  L.initialise([](const Vec3& x) { return Vec3(0.01 * (30 - x.y() * x.y() - x.z() * x.z()) / 30, 0.002 * std::sin(x.x()), 0.0); });
  Points X(200, 3);
  for (Eigen::Index k = 0; k < X.rows(); ++k) {
    const double t = 0.37 * k;
    X.row(k) << 7.0 * std::sin(0.11 * k) + 20.0 * (k % 3 - 1), 4.8 * std::cos(t) * (0.5 + 0.5 * std::sin(0.05 * k)), 4.8 * std::sin(t) * (0.5 + 0.5 * std::sin(0.05 * k));
  }
  IbInterpolator fast;
  for (int step = 0; step < 3; ++step) {
    for (IbKernel kernel : {IbKernel::Phi2, IbKernel::Phi3}) {
      Points Uref, U;
      interpolate_velocity(L, X, Uref, kernel);
      fast.interpolate(L, X, U, kernel);
      EXPECT_EQ(U, Uref) << "step " << step;
      // Spreading through the prepared stencils: the same force field, bit for bit.
      Points F(X.rows(), 3);
      for (Eigen::Index k = 0; k < X.rows(); ++k) F.row(k) << 1e-4 * std::sin(0.3 * k), 2e-5 * k, -3e-5;
      // On one thread and on several, where each owns a range of nodes.
      const int saved = omp_get_max_threads();
      for (int threads : {1, 2, 3}) {
        omp_set_num_threads(threads);
        Lattice a = L, b = L;
        a.clear_force();
        b.clear_force();
        spread_forces(a, X, F, kernel);
        fast.spread(b, F);
        for (int d = 0; d < 3; ++d)
          for (std::size_t node = 0; node < a.num_nodes(); ++node)
            ASSERT_EQ(a.force_data(d)[node], b.force_data(d)[node]) << "node " << node << ", " << threads << " threads";
        b.clear_force();  // the field written directly is cleared whole
        for (int d = 0; d < 3; ++d)
          for (std::size_t node = 0; node < b.num_nodes(); ++node) ASSERT_EQ(b.force_data(d)[node], 0.0);
      }
      omp_set_num_threads(saved);
    }
    L.clear_force();
    spread_forces(L, X, Points::Constant(X.rows(), 3, 1e-4));
    L.step();
  }
}
