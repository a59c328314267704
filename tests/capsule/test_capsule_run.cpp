#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <limits>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "bendlab/capsule/capsule_run.hpp"
#include "bendlab/capsule/checkpoint.hpp"
#include "bendlab/capsule/run_tolerances.hpp"
#include "bendlab/capsule/shear_units.hpp"
#include "bendlab/capsule/steady_statistics.hpp"
#include "bendlab/core/finite_check.hpp"
#include "bendlab/core/folder_lock.hpp"
#include "bendlab/flow/bim/bim_capsule_solver.hpp"
#include "bendlab/mesh/generators.hpp"
#include "file_test_support.hpp"

using namespace bendlab;
namespace fs = std::filesystem;
using bendlab::test_support::slurp;
using bendlab::test_support::spit;

namespace {

class CapsuleRun : public ::testing::Test {
 protected:
  void SetUp() override {
    dir = fs::temp_directory_path() /
          ("bendlab_capsule_" + std::to_string(::getpid()) + "_" +
           ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir);
    fs::create_directories(dir);
  }
  void TearDown() override { fs::remove_all(dir); }

  // 320 triangles, G = 0.1, no bending: the CLI's smallest shear run.
  static std::shared_ptr<const MembraneModel> membrane(int level = 2) {
    MembraneParameters p;
    p.kS = ShearUnits::from(0.1, 0.0, std::nullopt).kS();
    return std::make_shared<const MembraneModel>(sphere_mesh(MeshFamily::MT1, level), p);
  }
  static std::unique_ptr<BimCapsuleSolver> solver(int level = 2) {
    return std::make_unique<BimCapsuleSolver>(membrane(level));
  }
  CapsuleRunOptions options(const fs::path& folder, double t_end = 0.3) const {
    CapsuleRunOptions o;
    o.folder = folder;
    o.t_end = t_end;
    o.snapshot_every = 0.1;
    o.arguments = {{"solver", "bim"}, {"G", 0.1}, {"kappa_b_hat", 0.0}};
    return o;
  }

  fs::path dir;
};

}  // namespace

TEST(SteadyStatistics, WindowAndWeightedMeans) {
  EXPECT_EQ(SteadyWindow::for_run(10), (SteadyWindow{5, 10}));
  EXPECT_EQ(SteadyWindow::for_run(25), (SteadyWindow{5, 10}));
  EXPECT_EQ(SteadyWindow::for_run(4), (SteadyWindow{2, 4}));
  SteadyStatistics s(SteadyWindow::for_run(4));
  EXPECT_TRUE(std::isnan(s.D()));
  EXPECT_TRUE(std::isnan(s.mean_dt()));
  // Rows before the window are left out; each row in it is weighted by its step.
  s.add({1.0, 9.0, 9.0, 0, 0, 0, 0, 0.5});
  s.add({2.5, 0.2, 0.1, 0, 0, 0, 0, 0.5});
  s.add({3.0, 0.4, 0.4, 0, 0, 0, 0, 0.5});
  s.add({4.0, 0.1, 0.7, 0, 0, 0, 0, 1.0});
  s.add({4.0 + 1e-13, 0.1, 0.7, 0, 0, 0, 0, 1e-13});  // round-off past the end still counts
  EXPECT_EQ(s.count(), 4);
  const double w = 0.5 + 0.5 + 1.0 + 1e-13;
  EXPECT_NEAR(s.D(), (0.2 * 0.5 + 0.4 * 0.5 + 0.1 * 1.0 + 0.1 * 1e-13) / w, 1e-15);
  EXPECT_NEAR(s.theta(), (0.1 * 0.5 + 0.4 * 0.5 + 0.7 * 1.0 + 0.7 * 1e-13) / w, 1e-15);
  EXPECT_NEAR(s.mean_dt(), w / 4, 1e-15);
  // The running sums survive JSON text exactly.
  const SteadyStatistics back =
      SteadyStatistics::from_json(nlohmann::json::parse(s.to_json().dump()), "test");
  EXPECT_EQ(back.D(), s.D());
  EXPECT_EQ(back.theta(), s.theta());
  EXPECT_EQ(back.mean_dt(), s.mean_dt());
  EXPECT_EQ(back.window(), s.window());
  nlohmann::json bad = s.to_json();
  bad["count"] = -1;
  EXPECT_THROW(SteadyStatistics::from_json(bad, "test"), Error);
  bad = s.to_json();
  bad.erase("D_dt");
  try {
    SteadyStatistics::from_json(bad, "file.json");
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("D_dt"), std::string::npos) << e.what();
  }
}

TEST(TimeSeries, WhateverTheWriterWritesTheReaderReads) {
  // The extremes a run can produce: subnormals (energies of kS = 1/G at G = 1e308 came out as
  // 1.23301775164e-314), the largest and smallest normal numbers (the largest to 15 digits,
  // 1.79769313486232e+308, would be past it), infinities, signed zeros. Each row reads back to a
  // row that is written as the very same text.
  using L = std::numeric_limits<double>;
  for (const double v : {L::denorm_min(), 1.23301775164e-314, -2.5e-320, L::min(), -L::min(), L::max(), -L::max(),
                         L::infinity(), -L::infinity(), 0.0, -0.0, 1e-300}) {
    const TimeSeriesRow row{0.5, v, v, v, v, v, v, 0.01, v, v};
    const std::string line = format_time_series_row(row);
    std::vector<TimeSeriesRow> back;
    ASSERT_NO_THROW(back = parse_time_series(std::string(time_series_header()) + "\n" + line, "t.csv")) << line;
    ASSERT_EQ(back.size(), 1u);
    EXPECT_EQ(format_time_series_row(back[0]), line);
    if (v != 0 && std::isfinite(v)) {
      EXPECT_NE(back[0].D, 0.0) << line;
    }
  }
  // Numbers beyond the doubles are still refused, naming the line.
  for (const char* cell : {"1e400", "-1e999"}) {
    const std::string text = std::string(time_series_header()) + "\n0.5," + cell + ",0,0,0,0,0,0.01,0,0\n";
    try {
      parse_time_series(text, "t.csv");
      ADD_FAILURE() << cell;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("line 2"), std::string::npos) << e.what();
    }
  }
}

TEST_F(CapsuleRun, TimeSeriesResumeKeepsRowsByteForByte) {
  const fs::path p = dir / "timeseries.csv";
  {
    TimeSeriesFile f = TimeSeriesFile::create(p);
    for (int k = 1; k <= 5; ++k) f.append({0.1 * k, 0.01 * k, 0.2, 4.18, 12.5, NAN, 1e-3 * k, 0.1});
    EXPECT_EQ(f.rows(), 5);
  }
  const std::string full = slurp(p);
  const auto rows = read_time_series(p);
  ASSERT_EQ(rows.size(), 5u);
  EXPECT_TRUE(std::isnan(rows[2].E_bend));
  EXPECT_EQ(rows[4].D, 0.05);
  spit(p, full + "0.6,0.0");  // a torn last row, as a killed run may leave
  {
    TimeSeriesFile f = TimeSeriesFile::resume(p, 3);
    f.append(rows[3]);
    f.append(rows[4]);
  }
  EXPECT_EQ(slurp(p), full);
  // The rewrite is atomic: no temporary file is left beside it.
  for (const auto& e : fs::directory_iterator(dir)) EXPECT_EQ(e.path().filename(), "timeseries.csv");
  EXPECT_THROW(TimeSeriesFile::resume(p, 6), Error);  // fewer rows than the checkpoint needs
  EXPECT_EQ(slurp(p), full);                          // and the file is untouched
  spit(dir / "other.csv", "t,D\n");
  EXPECT_THROW(TimeSeriesFile::resume(dir / "other.csv", 0), Error);
}

TEST_F(CapsuleRun, FailedRowWriteIsAnError) {
  if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full";
  TimeSeriesFile f = TimeSeriesFile::append_to("/dev/full");
  try {
    f.append({0.1, 0, 0, 0, 0, 0, 0, 0.1});
    FAIL() << "writing to /dev/full succeeded";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("/dev/full"), std::string::npos) << e.what();
  }
}

TEST_F(CapsuleRun, ResumedRunEqualsUninterruptedRun) {
  const fs::path full = dir / "full", parts = dir / "parts";
  auto s1 = solver();
  const CapsuleRunResult r1 = run_capsule(*s1, options(full));
  ASSERT_TRUE(r1.finished);
  const std::int64_t steps = r1.summary.at("steps");
  ASSERT_GT(steps, 6);
  // Interrupt after most of the steps (past at least one snapshot), then resume in a fresh solver.
  CapsuleRunOptions o = options(parts);
  o.stop_after_steps = steps - 3;
  auto s2 = solver();
  EXPECT_FALSE(run_capsule(*s2, o).finished);
  EXPECT_FALSE(fs::exists(parts / "summary.json"));
  s2.reset();
  o.stop_after_steps = 0;
  o.resume = true;
  std::vector<std::string> notes;
  o.on_note = [&](const std::string& s) { notes.push_back(s); };
  auto s3 = solver();
  const CapsuleRunResult r3 = run_capsule(*s3, o);
  ASSERT_TRUE(r3.finished);
  ASSERT_FALSE(notes.empty());
  EXPECT_NE(notes.back().find("resuming"), std::string::npos);
  EXPECT_EQ(slurp(parts / "timeseries.csv"), slurp(full / "timeseries.csv"));
  // summary.json holds results only (the clock is in timing.json): the files are equal byte for byte.
  EXPECT_EQ(r3.summary, r1.summary);
  EXPECT_FALSE(r3.summary.contains("wall_seconds"));
  EXPECT_EQ(slurp(parts / "summary.json"), slurp(full / "summary.json"));
  const auto timing = nlohmann::json::parse(slurp(parts / "timing.json"));
  EXPECT_TRUE(timing.at("resumed").get<bool>());
  EXPECT_GE(timing.at("wall_seconds").get<double>(), timing.at("wall_seconds_last_part").get<double>());
  EXPECT_EQ(r3.wall_seconds, timing.at("wall_seconds").get<double>());
  EXPECT_EQ(slurp(parts / "shapes.pvd"), slurp(full / "shapes.pvd"));
  EXPECT_EQ(s3->positions(), s1->positions());

  // Extending the run moves the steady window: the sums are rebuilt from the file (D and theta with
  // 12 digits, dt with 6), and the new rows are added at full precision.
  o.t_end = 0.4;
  notes.clear();
  auto s5 = solver();
  const CapsuleRunResult r5 = run_capsule(*s5, o);
  ASSERT_TRUE(r5.finished);
  EXPECT_NE(notes.front().find("steady window"), std::string::npos);
  SteadyStatistics check(SteadyWindow::for_run(0.4));
  for (const TimeSeriesRow& row : read_time_series(parts / "timeseries.csv")) check.add(row);
  EXPECT_NEAR(r5.summary.at("D_steady").get<double>(), check.D(), 1e-6 * check.D());
  EXPECT_NEAR(r5.summary.at("theta_steady").get<double>(), check.theta(), 1e-6 * check.theta());
  EXPECT_EQ(r5.summary.at("steady_rows").get<std::int64_t>(), check.count());
  EXPECT_EQ(r5.summary.at("steady_window"), nlohmann::json({0.2, 0.4}));
}

TEST_F(CapsuleRun, CheckpointIsValidatedAsAWhole) {
  auto s = solver();
  CapsuleRunOptions o = options(dir / "run", 0.15);
  ASSERT_TRUE(run_capsule(*s, o).finished);
  const fs::path cp = dir / "run" / "checkpoint.json";
  const std::string good = slurp(cp);
  const int n = s->membrane().num_vertices();
  auto refused = [&](const std::string& text, const std::string& expected) {
    spit(cp, text);
    auto fresh = solver();
    CapsuleRunOptions r = o;
    r.resume = true;
    r.t_end = 0.2;  // after the checkpoint's time, so that only the checkpoint can be refused
    try {
      run_capsule(*fresh, r);
      ADD_FAILURE() << "accepted a checkpoint that should name " << expected;
    } catch (const Error& e) {
      const std::string msg = e.what();
      EXPECT_NE(msg.find(expected), std::string::npos) << msg;
      EXPECT_NE(msg.find("checkpoint"), std::string::npos) << msg;
    }
  };
  refused("", "empty");
  refused("{\"version\": 2, \"time\": ", "not valid JSON");
  refused("[1, 2]", "object");
  auto edited = [&](auto edit) {
    nlohmann::json j = nlohmann::json::parse(good);
    edit(j);
    return j.dump();
  };
  refused(edited([](auto& j) { j.erase("version"); j["arguments"] = {{"kappa_b", 0.1}}; }), "older bendlab");
  refused(edited([](auto& j) { j["version"] = 7; }), "\"version\"");
  refused(edited([](auto& j) { j.erase("positions"); }), "\"positions\" is missing");
  refused(edited([](auto& j) { j["positions"].erase(0); }), "\"positions\"");
  refused(edited([](auto& j) { j["positions"][4] = "x"; }), "entry 4");
  refused(edited([](auto& j) { j["vertices"] = 12; }), "\"vertices\"");
  refused(edited([](auto& j) { j["time"] = -1; }), "\"time\"");
  refused(edited([](auto& j) { j["steps"] = 1.5; }), "\"steps\"");
  refused(edited([](auto& j) { j["steps"] = 100000; }), "timeseries.csv");
  refused(edited([](auto& j) { j["counters"] = {{"rejected_steps", 0}}; }), "velocity_evaluations");
  refused(edited([](auto& j) { j["steady"]["count"] = "x"; }), "count");
  refused(edited([](auto& j) { j["snapshots"] = {{0.0, "../evil.vtp"}}; }), "snapshots");
  refused(edited([](auto& j) { j["snapshots"] = {{1e9, "snapshot_00000.vtp"}}; }), "snapshots");
  refused(edited([](auto& j) { j["solver_state"]["dt_next"] = nullptr; }), "dt_next");
  refused(edited([](auto& j) { j["solver"] = "lbm"; }), "solver");
  // The end a final checkpoint was written for lies at or before its own time.
  refused(edited([](auto& j) { j["final_for_t_end"] = 1.0; }), "\"final_for_t_end\"");
  refused(edited([](auto& j) { j["final_for_t_end"] = "x"; }), "\"final_for_t_end\"");
  {
    spit(cp, edited([](auto& j) { j["arguments"]["G"] = 0.2; }));
    auto fresh = solver();
    CapsuleRunOptions r = o;
    r.resume = true;
    try {
      run_capsule(*fresh, r);
      ADD_FAILURE() << "resumed a run with another G";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("G is 0.1 here but 0.2"), std::string::npos) << e.what();
    }
  }
  // The snapshot list names every snapshot of the run, in order, up to the checkpoint's time: an
  // empty or shortened list would make the resumed run overwrite snapshot_00000.vtp.
  refused(edited([](auto& j) { j["snapshots"] = nlohmann::json::array(); }), "\"snapshots\" is empty");
  refused(edited([](auto& j) { j["snapshots"].erase(j["snapshots"].size() - 1); }), "\"time\"");
  refused(edited([](auto& j) { j["snapshots"][0][1] = "snapshot_00001.vtp"; }), "expected 'snapshot_00000.vtp'");
  // A list two shorter, its time and steps edited to match: snapshot files beyond it are present.
  refused(edited([](auto& j) {
            j["snapshots"].erase(j["snapshots"].size() - 1);
            j["snapshots"].erase(j["snapshots"].size() - 1);
            j["time"] = j["snapshots"].back()[0];
            j.erase("final_for_t_end");  // no longer the run's final checkpoint
          }),
          "would overwrite");
  // A checkpoint names no file of the run as a side file to delete.
  refused(edited([](auto& j) { j["side_files"] = {"timeseries.csv"}; }), "\"side_files\" names 'timeseries.csv'");
  // The proposed step: none before the first step, and no larger than the controller proposes.
  refused(edited([](auto& j) { j["solver_state"]["dt_next"] = 0; }), "dt_next");
  refused(edited([](auto& j) { j["solver_state"]["dt_next"] = 1e308; }), "dt_next");
  // "time" and "steps" against the rows of timeseries.csv.
  const double t = nlohmann::json::parse(good).at("time").get<double>();
  refused(edited([&](auto& j) { j["time"] = t + 0.01; j["snapshots"].back()[0] = t + 0.01; }), "row");
  refused(edited([](auto& j) { j["steps"] = j["steps"].template get<int>() - 2; }), "row");
  EXPECT_EQ(slurp(dir / "run" / "snapshot_00000.vtp").empty(), false);
  EXPECT_EQ(n, s->membrane().num_vertices());
}

TEST_F(CapsuleRun, KeptRowsOfTheTimeSeriesAreParsedAndCrossChecked) {
  auto s = solver();
  const fs::path run = dir / "run";
  ASSERT_TRUE(run_capsule(*s, options(run, 0.15)).finished);
  const fs::path series = run / "timeseries.csv";
  const std::string good = slurp(series), checkpoint = slurp(run / "checkpoint.json");
  const std::size_t second = good.find('\n', good.find('\n') + 1) + 1;  // the start of row 2 (line 3)
  auto refused = [&](const std::string& text, const std::string& expected) {
    spit(series, text);
    auto fresh = solver();
    CapsuleRunOptions o = options(run, 0.2);
    o.resume = true;
    try {
      run_capsule(*fresh, o);
      ADD_FAILURE() << "accepted a time series that should name " << expected;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
    }
    EXPECT_EQ(slurp(series), text);  // refused before any change
    EXPECT_EQ(slurp(run / "checkpoint.json"), checkpoint);
  };
  refused(good.substr(0, second) + "garbage\n" + good.substr(good.find('\n', second) + 1), "line 3: 'garbage'");
  refused(good.substr(0, second) + "0.1,0.2,0.3,4,12,nan,0.001\n" + good.substr(good.find('\n', second) + 1),
          "line 3: 7 columns");
  refused(good.substr(0, second) + "0.1,0.2,0.3,4,12,nan,0.001,-0.01\n" + good.substr(good.find('\n', second) + 1),
          "line 3");
  // A folder in place of the file is named as such, not as an empty header.
  fs::remove(series);
  fs::create_directory(series);
  {
    auto fresh = solver();
    CapsuleRunOptions o = options(run, 0.2);
    o.resume = true;
    try {
      run_capsule(*fresh, o);
      ADD_FAILURE() << "accepted a folder as the time series";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("a folder"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("timeseries.csv"), std::string::npos) << e.what();
    }
  }
  fs::remove(series);
  spit(series, good);
  auto fresh = solver();
  CapsuleRunOptions o = options(run, 0.2);
  o.resume = true;
  EXPECT_TRUE(run_capsule(*fresh, o).finished);
}

TEST_F(CapsuleRun, ASecondRunIntoALockedFolderIsRefused) {
  const fs::path run = dir / "run";
  fs::create_directories(run);
  // Another process's lock, held here (flock locks conflict between open files, even in one process).
  FolderLock held(run, "run folder");
  auto s = solver();
  try {
    run_capsule(*s, options(run, 0.05));
    ADD_FAILURE() << "a second run into a locked folder was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("in use by another run"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(run / "timeseries.csv"));
}

TEST_F(CapsuleRun, ANewRunIntoAFolderHoldingARunNeedsOverwrite) {
  const fs::path run = dir / "run";
  auto s = solver();
  ASSERT_TRUE(run_capsule(*s, options(run, 0.3)).finished);
  ASSERT_TRUE(fs::exists(run / "snapshot_00003.vtp"));
  EXPECT_FALSE(fs::exists(run / ".lock"));  // released with the run
  spit(run / "notes.txt", "mine");
  const std::string series = slurp(run / "timeseries.csv"), summary = slurp(run / "summary.json");
  auto again = solver();
  try {
    run_capsule(*again, options(run, 0.1));
    ADD_FAILURE() << "a new run replaced another run without overwrite";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("holds another run"), std::string::npos) << e.what();
  }
  EXPECT_EQ(slurp(run / "timeseries.csv"), series);
  EXPECT_EQ(slurp(run / "summary.json"), summary);
  // With overwrite the old run's files go (its later snapshots too); other files stay.
  CapsuleRunOptions o = options(run, 0.1);
  o.overwrite = true;
  auto third = solver();
  ASSERT_TRUE(run_capsule(*third, o).finished);
  EXPECT_TRUE(fs::exists(run / "snapshot_00001.vtp"));
  EXPECT_FALSE(fs::exists(run / "snapshot_00002.vtp"));
  EXPECT_FALSE(fs::exists(run / "snapshot_00003.vtp"));
  EXPECT_EQ(slurp(run / "notes.txt"), "mine");
}

TEST_F(CapsuleRun, ResumeRemovesTheRunsStaleTemporariesOnly) {
  const fs::path run = dir / "run";
  auto s = solver();
  CapsuleRunOptions o = options(run, 0.3);
  o.stop_after_steps = 3;
  ASSERT_FALSE(run_capsule(*s, o).finished);
  // What a kill during writes leaves, and a file of someone else's.
  for (const char* f : {"snapshot_00001.vtp.tmpAb3dEf", "timeseries.csv.tmp4242zz", "checkpoint.json.tmpZZZZZZ"})
    spit(run / f, "half");
  spit(run / "mine.tmp", "keep");
  auto again = solver();
  o.stop_after_steps = 0;
  o.resume = true;
  ASSERT_TRUE(run_capsule(*again, o).finished);
  for (const auto& e : fs::directory_iterator(run))
    EXPECT_TRUE(e.path().filename() == "mine.tmp" || e.path().filename().string().find(".tmp") == std::string::npos)
        << e.path();
  EXPECT_EQ(slurp(run / "mine.tmp"), "keep");
}

TEST_F(CapsuleRun, ResumeAndOverwriteKeepFilesThatOnlyLookLikeTemporaries) {
  // Only "<output>.tmp" and mkstemp's six letters or digits can be a temporary of the run; any
  // other name after ".tmp" is a file of the user's, and survives --resume and --overwrite.
  // A step of a short run and its resume: cheap under the sanitizers.
  const fs::path run = dir / "run";
  auto s = solver();
  CapsuleRunOptions o = options(run, 0.01);
  o.stop_after_steps = 1;
  ASSERT_FALSE(run_capsule(*s, o).finished);
  const std::vector<std::string> users = {"timeseries.csv.tmp-backup-2024", "summary.json.tmp.mine",
                                          "checkpoint.json.tmp", "D_theta.png.tmp_by_user.png",
                                          "timing.json.tmp12345", "shapes.pvd.tmpABCDEFG"};
  for (const std::string& f : users) spit(run / f, "user's " + f);
  spit(run / "timeseries.csv.tmpQ9x2Lm", "half");  // a temporary of a killed write
  auto again = solver();
  o.stop_after_steps = 0;
  o.resume = true;
  ASSERT_TRUE(run_capsule(*again, o).finished);
  EXPECT_FALSE(fs::exists(run / "timeseries.csv.tmpQ9x2Lm"));
  for (const std::string& f : users) EXPECT_EQ(slurp(run / f), "user's " + f) << f << " after --resume";
  auto third = solver();  // --overwrite removes the old run's files as it starts: one step shows it
  o.resume = false;
  o.overwrite = true;
  o.stop_after_steps = 1;
  ASSERT_FALSE(run_capsule(*third, o).finished);
  EXPECT_FALSE(fs::exists(run / "summary.json"));
  for (const std::string& f : users) EXPECT_EQ(slurp(run / f), "user's " + f) << f << " after --overwrite";
}

TEST_F(CapsuleRun, AResumeToTheCheckpointsOwnEndWritesTheMissingSummary) {
  // A run stopped between its final checkpoint and summary.json (a kill, a failed summary write)
  // is completed by a resume with the same t_end: the summary the whole run would have written.
  const fs::path run = dir / "run";
  auto s = solver();
  const CapsuleRunResult whole = run_capsule(*s, options(run, 0.02));
  ASSERT_TRUE(whole.finished);
  const std::string series = slurp(run / "timeseries.csv");
  fs::remove(run / "summary.json");
  fs::remove(run / "timing.json");
  auto again = solver();
  CapsuleRunOptions o = options(run, 0.02);
  o.resume = true;
  const CapsuleRunResult completed = run_capsule(*again, o);
  ASSERT_TRUE(completed.finished);
  EXPECT_EQ(completed.summary, whole.summary);
  EXPECT_EQ(nlohmann::json::parse(slurp(run / "summary.json")), whole.summary);
  EXPECT_TRUE(fs::exists(run / "timing.json"));
  EXPECT_EQ(slurp(run / "timeseries.csv"), series);  // no step taken, no row added
  // An end before the checkpoint's is still refused.
  auto earlier = solver();
  o.t_end = 0.015;
  try {
    run_capsule(*earlier, o);
    ADD_FAILURE() << "resumed to an earlier end";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("is before the checkpoint"), std::string::npos) << e.what();
  }
}

TEST_F(CapsuleRun, AFolderWhoseParentIsMissingIsRefused) {
  auto s = solver();
  try {
    run_capsule(*s, options(dir / "a" / "b" / "c", 0.05));
    ADD_FAILURE() << "created missing parents";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("does not exist"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(dir / "a"));
}

TEST_F(CapsuleRun, FailedSnapshotWriteEndsTheRunAndKeepsTheCheckpoint) {
  // snapshot_00002.vtp cannot be written (a folder is in the way), as on a full or read-only disk.
  const fs::path run = dir / "run";
  fs::create_directories(run / "snapshot_00002.vtp" / "blocked");
  auto s = solver();
  try {
    run_capsule(*s, options(run));
    FAIL() << "the run succeeded";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("snapshot_00002.vtp"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(run / "summary.json"));
  // The checkpoint of the snapshot before is whole and valid.
  const CapsuleCheckpoint c = CapsuleCheckpoint::read(run / "checkpoint.json", s->membrane().num_vertices());
  ASSERT_EQ(c.snapshots.size(), 2u);
  EXPECT_NEAR(c.time, 0.1, 0.05);
  EXPECT_GT(static_cast<std::int64_t>(read_time_series(run / "timeseries.csv").size()), c.steps);
  // After clearing the obstacle the run resumes and finishes.
  fs::remove_all(run / "snapshot_00002.vtp");
  auto again = solver();
  CapsuleRunOptions o = options(run);
  o.resume = true;
  EXPECT_TRUE(run_capsule(*again, o).finished);
}

TEST_F(CapsuleRun, ManyRunsInOneProcess) {
  // Creating and destroying runs, solvers, membranes and meshes over and over is safe (run this
  // under the sanitizers: cmake --preset debug). 80 triangles and two steps each keep it fast there.
  for (int k = 0; k < 50; ++k) {
    auto s = solver(1);
    CapsuleRunOptions o = options(dir / ("run" + std::to_string(k % 3)), 0.002);
    o.snapshot_every = 0.001;
    o.overwrite = true;
    int progress = 0;
    o.on_progress = [&](const CapsuleProgress&) { ++progress; };
    const CapsuleRunResult r = run_capsule(*s, o);
    ASSERT_TRUE(r.finished);
    EXPECT_GE(progress, 1);
    EXPECT_GT(r.summary.at("steps").get<int>(), 0);
  }
}

TEST_F(CapsuleRun, ResumeToAnEarlierEndIsRefusedBeforeAnyChange) {
  // Resuming a run that reached gamma t = 0.15 with t_end < 0.15 would write a summary of a run
  // that did not end at t_end: refused, and the folder stays as it was. (t_end = 0.15 completes
  // the run's files: AResumeToTheCheckpointsOwnEndWritesTheMissingSummary.)
  auto s = solver();
  const fs::path run = dir / "run";
  ASSERT_TRUE(run_capsule(*s, options(run, 0.15)).finished);
  const std::string series = slurp(run / "timeseries.csv"), checkpoint = slurp(run / "checkpoint.json"),
                    summary = slurp(run / "summary.json");
  for (double t_end : {0.15 - 1e-9, 0.1}) {
    CapsuleRunOptions o = options(run, t_end);
    o.resume = true;
    auto fresh = solver();
    try {
      run_capsule(*fresh, o);
      ADD_FAILURE() << "resumed to t_end = " << t_end;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("is before the checkpoint's gamma t"), std::string::npos) << e.what();
    }
    EXPECT_EQ(slurp(run / "timeseries.csv"), series);
    EXPECT_EQ(slurp(run / "checkpoint.json"), checkpoint);
    EXPECT_EQ(slurp(run / "summary.json"), summary);
  }
}

namespace {
// A bending method whose forces turn NaN at vertex 7 from its `healthy`-th evaluation on: a run
// that blows up, deterministically.
class FailingMethod final : public BendingMethod {
 public:
  explicit FailingMethod(int healthy) : healthy_(healthy) {}
  std::string name() const override { return "failing"; }
  BendingResult compute(const Topology& t, const Points& x, double) const override {
    BendingResult r;
    r.force = Points::Zero(t.num_vertices(), 3);
    if (++calls_ > healthy_) r.force(7, 1) = std::numeric_limits<double>::quiet_NaN();
    (void)x;
    return r;
  }

 private:
  int healthy_;
  mutable int calls_ = 0;
};
}  // namespace

TEST_F(CapsuleRun, BlowUpIsDiagnosedAndKeepsTheLastCheckpoint) {
  MembraneParameters p;
  p.kS = ShearUnits::from(0.1, 0.0, std::nullopt).kS();
  p.kB = 1e-3;
  p.bending = std::make_shared<FailingMethod>(6 * 10);  // healthy for about 10 steps
  auto m = std::make_shared<const MembraneModel>(sphere_mesh(MeshFamily::MT1, 2), p);
  BimCapsuleSolver s(m);
  const fs::path run = dir / "run";
  CapsuleRunOptions o = options(run, 1.0);
  o.snapshot_every = 0.02;
  try {
    run_capsule(s, o);
    FAIL() << "the run did not notice the NaN";
  } catch (const NonFiniteError&) {
    FAIL() << "the run's error should be wrapped with the step and the checkpoint";
  } catch (const Error& e) {
    const std::string msg = e.what();
    for (const char* part : {"bending force of method failing", "vertex 7", "the run failed after step",
                             "gamma t = ", "checkpoint.json"})
      EXPECT_NE(msg.find(part), std::string::npos) << part << " missing in: " << msg;
    EXPECT_EQ(msg.find("volume gradient"), std::string::npos) << msg;
  }
  EXPECT_FALSE(fs::exists(run / "summary.json"));
  // The last checkpoint is whole, finite, and a run resumes from it (here with a healthy method).
  const CapsuleCheckpoint c = CapsuleCheckpoint::read(run / "checkpoint.json", m->num_vertices());
  EXPECT_GT(c.time, 0.0);
  EXPECT_TRUE(c.positions.allFinite());
  EXPECT_GE(static_cast<std::int64_t>(read_time_series(run / "timeseries.csv").size()), c.steps);
  p.bending = std::make_shared<FailingMethod>(1 << 30);
  BimCapsuleSolver healthy(std::make_shared<const MembraneModel>(sphere_mesh(MeshFamily::MT1, 2), p));
  CapsuleRunOptions r = o;
  r.resume = true;
  r.t_end = c.time + 0.01;
  EXPECT_TRUE(run_capsule(healthy, r).finished);
}

TEST(FiniteCheck, FirstNonFiniteRowAndMessage) {
  Points a = Points::Zero(5, 3);
  EXPECT_EQ(first_non_finite_row(a), -1);
  a(3, 2) = std::numeric_limits<double>::infinity();
  a(4, 0) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(first_non_finite_row(a), 3);
  Scalars v = Scalars::Ones(4);
  v(2) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(first_non_finite_row(v), 2);
  try {
    require_finite_rows(a, "stage X: the force");
    FAIL();
  } catch (const NonFiniteError& e) {
    EXPECT_EQ(e.row(), 3);
    EXPECT_NE(std::string(e.what()).find("stage X: the force is not finite at vertex 3"), std::string::npos);
  }
}

TEST(RunTolerances, LooseTolerancesAreRefusedOrWarned) {
  EXPECT_EQ(check_run_tolerances(1e-7, 1e-6), "");
  EXPECT_EQ(check_run_tolerances(1e-4, 1e-4), "");
  EXPECT_NE(check_run_tolerances(1e-3, 1e-6).find("--rtol"), std::string::npos);
  EXPECT_NE(check_run_tolerances(1e-7, 1e-2).find("--atol"), std::string::npos);
  for (auto [rtol, atol] : {std::pair{0.1, 0.1}, std::pair{1e-7, 0.011}, std::pair{0.02, 1e-6}, std::pair{0.0, 1e-6},
                            std::pair{-1.0, 1e-6}, std::pair{std::nan(""), 1e-6}})
    EXPECT_THROW(check_run_tolerances(rtol, atol), Error) << rtol << " " << atol;
}
