#include <fmt/format.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "bendlab/capsule/capsule_run.hpp"
#include "bendlab/capsule/checkpoint.hpp"
#include "bendlab/capsule/shear_units.hpp"
#include "bendlab/flow/lbm/lbm_capsule_solver.hpp"
#include "bendlab/membrane/espresso_volume_force.hpp"
#include "bendlab/mesh/generators.hpp"
#include "lbm/tiny_capsule.hpp"

using namespace bendlab;
namespace fs = std::filesystem;

namespace {

using test::membrane;
using test::tiny_options;

class LbmCapsule : public ::testing::Test {
 protected:
  void SetUp() override {
    dir = fs::temp_directory_path() / ("bendlab_lbm_capsule_" + std::to_string(::getpid()) + "_" +
                                       ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir);
    fs::create_directories(dir);
  }
  void TearDown() override { fs::remove_all(dir); }
  fs::path dir;
};

}  // namespace

TEST_F(LbmCapsule, UnitsAndSampling) {
  const LbmSolverOptions o = tiny_options();
  LbmCapsuleSolver s(membrane(), o);
  EXPECT_EQ(s.name(), "lbm");
  EXPECT_EQ(s.time(), 0.0);
  // The run's positions are the lattice ones over R, centred on the box centre.
  EXPECT_EQ((s.lattice_positions() / o.radius - s.positions()).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_LT(s.positions().colwise().mean().norm(), 1e-12);
  // kS = 1/G maps to the lattice's mu gamma R / G: a force kS L of the run's units (L in R) is the
  // lattice's kS_lattice (R L).
  EXPECT_NEAR(s.force_scale() * s.membrane().kS(), o.lattice.kS * o.radius, 1e-15);
  EXPECT_EQ(s.sample_steps(), std::llround(0.01 / o.lattice.shear_rate));
  std::vector<double> times, dts;
  s.advance(0.05, [&](const AcceptedStep& a) {
    times.push_back(a.time);
    dts.push_back(a.dt);
    return true;
  });
  // One report every sample_steps lattice steps, the last one at or past t_end; dt sums to the time.
  ASSERT_FALSE(times.empty());
  EXPECT_GE(times.back(), 0.05);
  EXPECT_LT(times.back() - 0.05, o.lattice.shear_rate * 1.0000001);
  double sum = 0;
  for (double d : dts) sum += d;
  EXPECT_NEAR(sum, times.back(), 1e-12);
  EXPECT_EQ(s.counters().velocity_evaluations, s.lattice().step_count());
  // The capsule stays centred: the centred shear flow carries it nowhere (symmetry), to round-off.
  EXPECT_LT(s.positions().colwise().mean().norm(), 1e-9);
}

TEST_F(LbmCapsule, ResumedSolverRepeatsTheUninterruptedOneBitForBit) {
  LbmCapsuleSolver full(membrane(), tiny_options());
  for (int i = 0; i < 300; ++i) full.step();

  LbmCapsuleSolver first(membrane(), tiny_options());
  for (int i = 0; i < 130; ++i) first.step();
  const SolverState st = first.save_state(dir, "00001");
  ASSERT_EQ(st.side_files.size(), 1u);
  EXPECT_TRUE(fs::exists(dir / st.side_files[0]));
  // Through the JSON text, as a checkpoint stores it.
  const nlohmann::json fields = nlohmann::json::parse(st.fields.dump());

  LbmCapsuleSolver second(membrane(), tiny_options());
  second.restore_state(first.positions(), first.time(), first.counters(), fields, dir, "checkpoint.json");
  EXPECT_EQ(second.time(), first.time());
  for (int i = 0; i < 170; ++i) second.step();
  EXPECT_EQ(second.lattice().step_count(), full.lattice().step_count());
  EXPECT_TRUE((second.lattice_positions().array() == full.lattice_positions().array()).all());
  EXPECT_TRUE(second.lattice().raw_populations() == full.lattice().raw_populations());
  EXPECT_EQ(second.counters().velocity_evaluations, full.counters().velocity_evaluations);
  // The capsule has moved and deformed by then (the test is not trivial).
  EXPECT_GT((full.positions() - second.membrane().reference_positions()).cwiseAbs().maxCoeff(), 1e-4);
}

TEST_F(LbmCapsule, RestoreRefusesBadState) {
  LbmCapsuleSolver s(membrane(), tiny_options());
  for (int i = 0; i < 10; ++i) s.step();
  const SolverState st = s.save_state(dir, "00000");
  LbmCapsuleSolver r(membrane(), tiny_options());
  nlohmann::json f = st.fields;
  f["fluid"] = "missing.bin";
  EXPECT_THROW(r.restore_state(s.positions(), s.time(), s.counters(), f, dir, "c.json"), Error);
  f = st.fields;
  f["lattice_step"] = 11;
  EXPECT_THROW(r.restore_state(s.positions(), s.time(), s.counters(), f, dir, "c.json"), Error);
  f = st.fields;
  f["positions_lattice"].erase(0);
  EXPECT_THROW(r.restore_state(s.positions(), s.time(), s.counters(), f, dir, "c.json"), Error);
  // A fluid file of another lattice.
  LbmSolverOptions other = tiny_options();
  other.lattice.tau = 0.8;
  LbmCapsuleSolver o(membrane(), other);
  EXPECT_THROW(o.restore_state(s.positions(), s.time(), s.counters(), st.fields, dir, "c.json"), Error);
}

TEST_F(LbmCapsule, RunResumedFromItsCheckpointEqualsTheUninterruptedRun) {
  auto options = [&](const fs::path& folder) {
    CapsuleRunOptions o;
    o.folder = folder;
    o.t_end = 0.3;
    o.snapshot_every = 0.1;
    o.arguments = {{"solver", "lbm"}, {"G", 0.2}, {"kappa_b_hat", 0.0}};
    return o;
  };
  LbmCapsuleSolver a(membrane(), tiny_options());
  const CapsuleRunResult full = run_capsule(a, options(dir / "full"));
  ASSERT_TRUE(full.finished);

  LbmCapsuleSolver b(membrane(), tiny_options());
  CapsuleRunOptions o = options(dir / "parts");
  o.stop_after_steps = 15;  // past the first checkpoint at gamma t = 0.1 (10 reports)
  EXPECT_FALSE(run_capsule(b, o).finished);
  LbmCapsuleSolver c(membrane(), tiny_options());
  o.stop_after_steps = 0;
  o.resume = true;
  const CapsuleRunResult resumed = run_capsule(c, o);
  ASSERT_TRUE(resumed.finished);
  nlohmann::json x = full.summary, y = resumed.summary;
  EXPECT_EQ(x, y);
  EXPECT_TRUE((a.lattice_positions().array() == c.lattice_positions().array()).all());
  // Only the last checkpoint's fluid file is kept.
  int fluids = 0;
  for (const auto& e : fs::directory_iterator(dir / "parts"))
    if (e.path().filename().string().rfind("lbm_fluid_", 0) == 0) ++fluids;
  EXPECT_EQ(fluids, 1);
}

TEST_F(LbmCapsule, BlowUpNamesTheStepAndKeepsTheLastCheckpoint) {
  // G = 1e-5: the membrane is far too stiff for the explicit IB step and the run blows up.
  LbmCapsuleSolver s(membrane(1e-5), tiny_options(1e-5));
  CapsuleRunOptions o;
  o.folder = dir / "run";
  o.t_end = 1;
  o.snapshot_every = 0.02;
  o.arguments = {{"solver", "lbm"}};
  try {
    run_capsule(s, o);
    FAIL() << "no blow-up";
  } catch (const Error& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("step "), std::string::npos) << m;
    EXPECT_NE(m.find("node"), std::string::npos) << m;
  }
  const CapsuleCheckpoint c = CapsuleCheckpoint::read(o.folder / "checkpoint.json", s.membrane().num_vertices());
  EXPECT_TRUE(c.positions.allFinite());
  EXPECT_TRUE(fs::exists(o.folder / c.solver_state.fields.at("fluid").get<std::string>()));
}

TEST_F(LbmCapsule, OffsetMovesTheCapsuleAgainstTheLattice) {
  LbmSolverOptions o = tiny_options();
  o.offset = Vec3(0.5, -0.25, 0.0);
  LbmCapsuleSolver s(membrane(), o);
  const Vec3 centroid = s.lattice_positions().colwise().mean().transpose();
  EXPECT_LT((centroid - o.offset).norm(), 1e-12);
  EXPECT_EQ((s.lattice_positions() / o.radius - s.positions()).cwiseAbs().maxCoeff(), 0.0);
  // x and y are periodic: a whole dx along either is the same discrete problem, so the shape
  // (about its centroid) evolves the same to rounding; half a dx is a different sampling.
  auto shape_after = [&](const Vec3& offset) {
    LbmSolverOptions oo = tiny_options();
    oo.offset = offset;
    LbmCapsuleSolver c(membrane(), oo);
    for (int i = 0; i < 60; ++i) c.step();
    Points x = c.positions();
    x.rowwise() -= x.colwise().mean();
    return x;
  };
  const Points base = shape_after(Vec3::Zero());
  const Points shifted = shape_after(Vec3(1.0, -1.0, 0.0));
  const Points half = shape_after(Vec3(0.5, 0.5, 0.0));
  Points start = membrane()->reference_positions();
  start.rowwise() -= start.colwise().mean();
  const double deformed = (base - start).cwiseAbs().maxCoeff();
  const double whole = (shifted - base).cwiseAbs().maxCoeff(), halfway = (half - base).cwiseAbs().maxCoeff();
  RecordProperty("deformed", std::to_string(deformed));
  RecordProperty("whole", fmt::format("{:.3e}", whole));
  RecordProperty("halfway", std::to_string(halfway));
  EXPECT_GT(deformed, 1e-6);
  EXPECT_LT(whole, 1e-10 * deformed);
  EXPECT_GT(halfway, 1e3 * whole);
  // Offsets beyond one dx are refused before any work.
  o.offset = Vec3(0.0, 0.0, 1.5);
  EXPECT_THROW(LbmCapsuleSolver(membrane(), o), Error);
  o.offset = Vec3(std::nan(""), 0.0, 0.0);
  EXPECT_THROW(LbmCapsuleSolver(membrane(), o), Error);
}
