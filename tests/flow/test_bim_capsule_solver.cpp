#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "bendlab/capsule/capsule_run.hpp"
#include "bendlab/capsule/shear_units.hpp"
#include "bendlab/flow/bim/bim_capsule_solver.hpp"
#include "bendlab/flow/volume_correction.hpp"
#include "bendlab/geometry/measures.hpp"
#include "bendlab/bending/method_registry.hpp"
#include "bendlab/integrate/cash_karp.hpp"
#include "bendlab/integrate/rkc.hpp"
#include "bendlab/mesh/generators.hpp"

using namespace bendlab;

namespace {
std::shared_ptr<const MembraneModel> membrane(const TriMesh& m, double G) {
  MembraneParameters p;
  p.kS = ShearUnits::from(G, 0.0, std::nullopt).kS();
  return std::make_shared<const MembraneModel>(m, p);
}
}  // namespace

TEST(BimCapsuleSolver, ShortRunConservesVolumeAndDeforms) {
  const TriMesh m = sphere_mesh(MeshFamily::MT1, 2);  // 320 triangles
  BimCapsuleSolver sim(membrane(m, 0.1));
  EXPECT_DOUBLE_EQ(sim.membrane().kS(), 10.0);
  const double v0 = enclosed_volume(m.topology(), m.positions());
  std::vector<TimeSeriesRow> rows;
  double max_dv = 0;
  ASSERT_TRUE(sim.advance(0.5, [&](const AcceptedStep& s) {
    rows.push_back(capsule_sample(sim.membrane(), *s.positions, s.time, s.dt));
    max_dv = std::max(max_dv, std::abs(rows.back().volume - v0) / v0);
    return true;
  }));
  ASSERT_FALSE(rows.empty());
  EXPECT_DOUBLE_EQ(rows.back().t, 0.5);
  EXPECT_DOUBLE_EQ(sim.time(), 0.5);
  EXPECT_LT(max_dv, 1e-10);
  // Starting from a sphere, D grows monotonically at first; at gamma t = 0.5 and G = 0.1 it is
  // well above zero.
  EXPECT_GT(rows.back().D, 0.05);
  for (std::size_t k = 1; k < rows.size(); ++k) EXPECT_GT(rows[k].D, rows[k - 1].D);
  // The long axis leans into the extensional quadrant of u = gamma z e_x.
  EXPECT_GT(rows.back().theta, 0.0);
  EXPECT_LT(rows.back().theta, M_PI / 2);
  EXPECT_GT(rows.back().E_elastic, 0.0);
  EXPECT_TRUE(std::isnan(rows.back().E_bend));  // no bending method
  // Six evaluations per attempted step.
  const SolverCounters c = sim.counters();
  EXPECT_EQ(c.velocity_evaluations, 6 * (static_cast<std::int64_t>(rows.size()) + c.rejected_steps));
  // The centroid stays at the origin: u_inf is odd about it and the forces are balanced.
  EXPECT_LT(volume_centroid(m.topology(), sim.positions()).norm(), 1e-6);
}

TEST(BimCapsuleSolver, EarlyShapeIsTheAffineShear) {
  // The initial sphere is force-free, so at first it moves with u_inf = gamma z e_x itself: an
  // affine simple shear x -> x + gamma t z e_x, whose principal stretches are 1 +- gamma t / 2 +
  // O(t^2). Hence D = gamma t / 2 + O(t^2) (the sphere mesh's second moment is isotropic, so the
  // polyhedral D is the continuum one) and theta -> pi/4.
  const TriMesh m = sphere_mesh(MeshFamily::MT1, 2);
  BimCapsuleSolver sim(membrane(m, 0.1));
  sim.advance(1e-3, {});
  const TimeSeriesRow last = capsule_sample(sim.membrane(), sim.positions(), sim.time(), 0);
  EXPECT_NEAR(last.D, 0.5 * last.t, 0.02 * 0.5 * last.t);
  EXPECT_NEAR(last.theta, M_PI / 4, 0.01);
  // The right-hand side has zero discrete flux after the projection.
  Points u, a;
  sim.velocity(sim.positions(), u);
  volume_gradient(m.topology(), sim.positions(), a);
  EXPECT_LT(std::abs(discrete_flux(a, u)), 1e-14 * a.cwiseAbs().sum() * u.cwiseAbs().maxCoeff());
}

TEST(BimCapsuleSolver, RestoredStateContinuesTheSameTrajectory) {
  const TriMesh m = sphere_mesh(MeshFamily::MT1, 1);  // 80 triangles: cheap
  const auto mem = membrane(m, 0.2);
  BimCapsuleSolver full(mem);
  full.advance(0.4, {});
  // Stop half-way, then resume a fresh solver from the saved state and step.
  BimCapsuleSolver first(mem);
  Points saved;
  double t_saved = 0;
  EXPECT_FALSE(first.advance(0.4, [&](const AcceptedStep& s) {
    if (s.time < 0.2) return true;
    saved = *s.positions;
    t_saved = s.time;
    return false;
  }));
  ASSERT_GT(t_saved, 0.0);
  const SolverState state = first.save_state({}, "0");
  BimCapsuleSolver resumed(mem);
  resumed.restore_state(saved, t_saved, first.counters(), state.fields, {}, "test");
  resumed.advance(0.4, {});
  EXPECT_DOUBLE_EQ(resumed.time(), 0.4);
  // Same state and same proposed step: the resumed run repeats the uninterrupted one step by step.
  EXPECT_EQ(resumed.positions(), full.positions());
  EXPECT_EQ(resumed.counters().velocity_evaluations, full.counters().velocity_evaluations);
  EXPECT_EQ(resumed.counters().rejected_steps, full.counters().rejected_steps);
  EXPECT_THROW(resumed.restore_state(saved, t_saved, {}, nlohmann::json{{"dt_next", "x"}}, {}, "test"), Error);
}

TEST(BimCapsuleSolver, RejectsBadParameters) {
  const TriMesh m = sphere_mesh(MeshFamily::MT1, 0);
  EXPECT_THROW(BimCapsuleSolver(nullptr), Error);
  BimOptions o;
  o.mu = 0;
  EXPECT_THROW(BimCapsuleSolver(membrane(m, 0.1), nullptr, o), Error);
  EXPECT_THROW(ShearUnits::from(0, 0.0, std::nullopt), Error);
  EXPECT_THROW(ShearUnits::from(0.1, 0.1, 0.1), Error);  // both moduli
  MembraneParameters p;
  p.kB = 0.1;  // bending without a method
  EXPECT_THROW(MembraneModel(m, p), Error);
}

namespace {
// The paper's stiff case (G = 0.2, kappa_b_hat = 0.15, Method C) at 320 triangles.
std::shared_ptr<const MembraneModel> bending_membrane() {
  const TriMesh m = sphere_mesh(MeshFamily::MT1, 2);
  const ShearUnits u = ShearUnits::from(0.2, 0.15, std::nullopt);
  MembraneParameters p;
  p.kS = u.kS();
  p.kB = u.kB();
  p.bending = make_bending_method("C", {});
  return std::make_shared<const MembraneModel>(m, p);
}

std::unique_ptr<Integrator> rkc(double rtol, double atol) {
  RkcOptions o;
  o.rtol = rtol;
  o.atol = atol;
  o.spectral_interval = 5;  // several estimates within a short run, one across the interruption
  return std::make_unique<Rkc>(o);
}
}  // namespace

TEST(BimCapsuleSolver, RkcRestoredStateContinuesTheSameTrajectory) {
  const auto mem = bending_membrane();
  BimCapsuleSolver full(mem, rkc(1e-7, 1e-6));
  full.advance(0.3, {});
  BimCapsuleSolver first(mem, rkc(1e-7, 1e-6));
  Points saved;
  double t_saved = 0;
  SolverState state;
  SolverCounters counters;
  int steps = 0;
  EXPECT_FALSE(first.advance(0.3, [&](const AcceptedStep& s) {
    if (++steps < 7) return true;  // past one re-estimate of the spectral radius, before the next
    saved = *s.positions;
    t_saved = s.time;
    state = first.save_state({}, "0");  // inside the step, as run_capsule does
    counters = first.counters();
    return false;
  }));
  ASSERT_GT(t_saved, 0.0);
  ASSERT_TRUE(state.fields.contains("integrator"));
  EXPECT_EQ(state.fields["integrator"]["name"], "rkc");
  EXPECT_EQ(state.fields["integrator"]["state"]["spectral_vector"].size(), 3u * mem->num_vertices());
  // Through text, as a checkpoint file stores it.
  const nlohmann::json fields = nlohmann::json::parse(state.fields.dump());
  BimCapsuleSolver resumed(mem, rkc(1e-7, 1e-6));
  resumed.restore_state(saved, t_saved, counters, fields, {}, "test");
  resumed.advance(0.3, {});
  EXPECT_EQ(resumed.positions(), full.positions());
  EXPECT_EQ(resumed.counters().velocity_evaluations, full.counters().velocity_evaluations);
  EXPECT_EQ(resumed.counters().rejected_steps, full.counters().rejected_steps);
  EXPECT_EQ(resumed.summary(), full.summary());
  EXPECT_EQ(full.summary()["integrator"], "rkc");
  EXPECT_GE(full.summary()["integrator_stats"]["mean_stages"].get<double>(), 2.0);
  // A Cash-Karp solver refuses RKC's state; RKC refuses a damaged one.
  BimCapsuleSolver ck(mem);
  EXPECT_THROW(ck.restore_state(saved, t_saved, {}, fields, {}, "test"), Error);
  nlohmann::json bad = fields;
  bad["integrator"]["state"].erase("spectral_radius");
  BimCapsuleSolver other(mem, rkc(1e-7, 1e-6));
  other.restore_state(saved, t_saved, {}, bad, {}, "test");
  EXPECT_THROW(other.advance(0.3, {}), Error);
}

TEST(BimCapsuleSolver, RkcErrorFallsAsTheToleranceIsTightened) {
  // D(t_end) of RKC against a tight Cash-Karp reference, in the stiff case: RKC's error estimate
  // is of the position, so D's error must fall with the tolerance: a second-order method with the
  // step ~ rtol^(1/3) has a global error ~ rtol^(2/3), a factor 21.5 per two decades (measured at
  // 1e-4, 1e-6, 1e-8: 16 and 19, the error dominated by the fast start from the sphere); asserted
  // is a factor of more than 8 per two decades.
  const auto mem = bending_membrane();
  const double t_end = 0.5;
  auto D_at_end = [&](std::unique_ptr<Integrator> integrator) {
    BimCapsuleSolver sim(mem, std::move(integrator));
    sim.advance(t_end, {});
    return capsule_sample(sim.membrane(), sim.positions(), sim.time(), 0).D;
  };
  CashKarpOptions ck;
  ck.rtol = 1e-11;
  ck.atol = 1e-10;
  const double reference = D_at_end(std::make_unique<CashKarp>(ck));
  std::vector<double> errors;
  for (const double rtol : {1e-4, 1e-6, 1e-8}) errors.push_back(std::abs(D_at_end(rkc(rtol, 10 * rtol)) - reference));
  EXPECT_GT(reference, 0.1);
  EXPECT_LT(errors[1], errors[0] / 8);
  EXPECT_LT(errors[2], errors[1] / 8);
  EXPECT_LT(errors[2], 2e-5 * reference);
  EXPECT_LT(errors[0], 1e-2 * reference);
}
