#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "bendlab/flow/shear_simulation.hpp"
#include "bendlab/flow/volume_correction.hpp"
#include "bendlab/geometry/measures.hpp"
#include "bendlab/mesh/generators.hpp"

using namespace bendlab;

TEST(ShearSimulation, ShortRunConservesVolumeAndDeforms) {
  const TriMesh m = sphere_mesh(MeshFamily::MT1, 2);  // 320 triangles
  ShearParameters p;
  p.G = 0.1;
  p.t_end = 0.5;
  ShearSimulation sim(m, p);
  EXPECT_DOUBLE_EQ(sim.kS(), 10.0);
  const double v0 = enclosed_volume(m.topology(), m.positions());
  std::vector<ShearSample> samples;
  double max_dv = 0;
  const auto st = sim.run([&](const ShearSample& s) {
    max_dv = std::max(max_dv, std::abs(s.volume - v0) / v0);
    samples.push_back(s);
    samples.back().positions = nullptr;
    return true;
  });
  ASSERT_FALSE(samples.empty());
  EXPECT_DOUBLE_EQ(samples.back().time, 0.5);
  EXPECT_DOUBLE_EQ(sim.time(), 0.5);
  EXPECT_LT(max_dv, 1e-10);
  // Starting from a sphere, D grows monotonically at first; at gamma t = 0.5 and G = 0.1 it is
  // well above zero.
  EXPECT_GT(samples.back().D, 0.05);
  for (std::size_t k = 1; k < samples.size(); ++k) EXPECT_GT(samples[k].D, samples[k - 1].D);
  // The long axis leans into the extensional quadrant of u = gamma z e_x.
  EXPECT_GT(samples.back().theta, 0.0);
  EXPECT_LT(samples.back().theta, M_PI / 2);
  EXPECT_GT(samples.back().E_elastic, 0.0);
  EXPECT_FALSE(samples.back().E_bend.has_value());
  EXPECT_EQ(st.accepted, static_cast<std::int64_t>(samples.size()));
  // The centroid stays at the origin: u_inf is odd about it and the forces are balanced.
  EXPECT_LT(volume_centroid(m.topology(), sim.positions()).norm(), 1e-6);
}

TEST(ShearSimulation, EarlyShapeIsTheAffineShear) {
  // The initial sphere is force-free, so at first it moves with u_inf = gamma z e_x itself: an
  // affine simple shear x -> x + gamma t z e_x, whose principal stretches are 1 +- gamma t / 2 +
  // O(t^2). Hence D = gamma t / 2 + O(t^2) (the sphere mesh's second moment is isotropic, so the
  // polyhedral D is the continuum one) and theta -> pi/4.
  const TriMesh m = sphere_mesh(MeshFamily::MT1, 2);
  ShearParameters p;
  p.G = 0.1;
  p.t_end = 1e-3;
  ShearSimulation sim(m, p);
  ShearSample last;
  sim.run([&](const ShearSample& s) {
    last = s;
    return true;
  });
  EXPECT_NEAR(last.D, 0.5 * last.time, 0.02 * 0.5 * last.time);
  EXPECT_NEAR(last.theta, M_PI / 4, 0.01);
  // The right-hand side has zero discrete flux after the projection.
  Points u, a;
  sim.velocity(sim.positions(), u);
  volume_gradient(m.topology(), sim.positions(), a);
  EXPECT_LT(std::abs(discrete_flux(a, u)), 1e-14 * a.cwiseAbs().sum() * u.cwiseAbs().maxCoeff());
}

TEST(ShearSimulation, RestartContinuesTheSameTrajectory) {
  const TriMesh m = sphere_mesh(MeshFamily::MT1, 1);  // 80 triangles: cheap
  ShearParameters p;
  p.G = 0.2;
  p.t_end = 0.4;
  ShearSimulation full(m, p);
  full.run();
  // Stop half-way, then resume a fresh simulation from the saved state and step.
  ShearSimulation first(m, p);
  Points saved;
  double t_saved = 0, dt_saved = 0;
  first.run([&](const ShearSample& s) {
    if (s.time < 0.2) return true;
    saved = *s.positions;
    t_saved = s.time;
    dt_saved = s.dt_next;
    EXPECT_EQ(s.dt_next, first.dt_next());
    return false;
  });
  EXPECT_EQ(dt_saved, first.dt_next());
  ASSERT_GT(t_saved, 0.0);
  ShearSimulation resumed(m, p);
  resumed.restart(saved, t_saved, dt_saved);
  resumed.run();
  EXPECT_DOUBLE_EQ(resumed.time(), 0.4);
  // Same state and same proposed step: the resumed run repeats the uninterrupted one step by step.
  EXPECT_LT((resumed.positions() - full.positions()).cwiseAbs().maxCoeff(), 1e-13);
}

TEST(ShearSimulation, RejectsBadParameters) {
  const TriMesh m = sphere_mesh(MeshFamily::MT1, 0);
  ShearParameters p;
  p.G = 0;
  EXPECT_THROW(ShearSimulation(m, p), Error);
  p.G = 0.1;
  p.kappa_b_hat = 0.1;  // bending without a method
  EXPECT_THROW(ShearSimulation(m, p), Error);
}
