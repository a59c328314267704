// A deterministic mutation fuzzer for the readers of a capsule run's folder: the checkpoint JSON
// reader (CapsuleCheckpoint::parse, what CapsuleCheckpoint::read does after reading the file) and
// the time-series CSV reader (parse_time_series). The seeds are the files of a real two-step run;
// they are mutated byte-wise (bit flips, insertions, deletions, duplicated and truncated ranges,
// tokens replaced by extreme or malformed numbers) and, for the checkpoint, also structurally
// (a value of the JSON document replaced by one of another type or range, or removed). Every
// input must either be accepted or refused with bendlab::Error naming the source: no other
// exception, and (under the debug preset's AddressSanitizer and UBSan) no crash. The generator's
// seed is fixed, so a failure reproduces; BENDLAB_FUZZ_INPUTS sets the inputs per reader
// (default 5000 checkpoints, each a 5 kB document, and 25000 time series: a few seconds each in
// a release build, so that the sanitizer build stays within its budget).
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <random>
#include <string>
#include <vector>

#include "bendlab/capsule/capsule_run.hpp"
#include "bendlab/capsule/checkpoint.hpp"
#include "bendlab/capsule/shear_units.hpp"
#include "bendlab/capsule/time_series.hpp"
#include "bendlab/core/file_input.hpp"
#include "bendlab/flow/bim/bim_capsule_solver.hpp"
#include "bendlab/mesh/generators.hpp"
#include "core/byte_mutation.hpp"
#include "file_test_support.hpp"

namespace fs = std::filesystem;
using bendlab::test_support::spit;
using namespace bendlab;

namespace {

long inputs_per_reader(long default_inputs) {
  if (const char* s = std::getenv("BENDLAB_FUZZ_INPUTS")) return std::max(1L, std::atol(s));
  return default_inputs;
}

constexpr int kLevel = 1;  // 80 triangles, 42 vertices

struct RunFiles {
  std::string checkpoint, series;
  int vertices = 0;
};

/// checkpoint.json and timeseries.csv of a two-step run of the smallest capsule.
RunFiles run_files() {
  const fs::path dir = fs::temp_directory_path() / ("bendlab_capsule_fuzz_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  MembraneParameters p;
  p.kS = ShearUnits::from(0.1, 0.0, std::nullopt).kS();
  auto membrane = std::make_shared<const MembraneModel>(sphere_mesh(MeshFamily::MT1, kLevel), p);
  BimCapsuleSolver solver(membrane);
  CapsuleRunOptions o;
  o.folder = dir;
  o.t_end = 0.002;
  o.snapshot_every = 0.001;
  o.arguments = {{"solver", "bim"}, {"G", 0.1}, {"kappa_b_hat", 0.0}};
  run_capsule(solver, o);
  RunFiles f{read_regular_file(dir / "checkpoint.json"), read_regular_file(dir / "timeseries.csv"),
             membrane->num_vertices()};
  fs::remove_all(dir);
  return f;
}

const std::vector<std::string> kTokens = {"-1", "0", "1", "2", "-0", "1e308", "-1e308", "1e999", "1e-320", "nan", "inf",
                               "-inf", "nan(1)", "0x1p3", "+", "-", ".", "e5", "9223372036854775807",
                               "9223372036854775808", "-9223372036854775809", "18446744073709551616", "\"\"",
                               "\"x\"", "null", "true", "[]", "{}", "[[", "]}", ",", ",,", "\n", "\r\n", " ",
                               "\"../x.vtp\"", "\"snapshot_99999.vtp\"", "\"\\u0000\"", "\"\\ud800\""};

std::string mutate_file(const std::string& seed, std::mt19937_64& rng) {
  return test::mutate_bytes(seed, rng, kTokens, ",:[]{}\n");
}

/// A value of the document replaced by one of another type or range, or removed.
std::string mutate_structure(const nlohmann::json& seed, std::mt19937_64& rng) {
  nlohmann::json flat = seed.flatten();
  const std::vector<nlohmann::json> values = {
      nullptr, true, -1, 0, 1, 2, 0.5, -1e308, 1e308, 9223372036854775807LL, "x", "", "../evil.vtp",
      nlohmann::json::array(), nlohmann::json::object(), nlohmann::json::array({1, 2}), {{"a", 1}}};
  const int mutations = 1 + static_cast<int>(rng() % 3);
  for (int m = 0; m < mutations && !flat.empty(); ++m) {
    auto it = flat.begin();
    std::advance(it, static_cast<long>(rng() % flat.size()));
    if (rng() % 4 == 0)
      flat.erase(it);
    else
      *it = values[rng() % values.size()];
  }
  try {
    return flat.unflatten().dump();
  } catch (const nlohmann::json::exception&) {
    return flat.dump();  // not unflattenable (an object or array put in a leaf's place): still an input
  }
}

struct Outcome {
  long accepted = 0, refused = 0;
};

template <class Parse>
void expect_accepted_or_error(const std::string& input, const std::string& source, Parse parse, Outcome& out,
                              long i) {
  try {
    parse(input);
    ++out.accepted;
  } catch (const Error& e) {
    ++out.refused;
    ASSERT_NE(std::string(e.what()).find(source), std::string::npos) << "an error must name the file: " << e.what();
  } catch (const std::exception& e) {
    FAIL() << "input " << i << ": not a bendlab::Error: " << e.what() << "\n" << input.substr(0, 2000);
  }
}

}  // namespace

TEST(CapsuleReaderFuzz, EveryMutatedCheckpointIsAcceptedOrRefusedWithError) {
  const RunFiles files = run_files();
  const std::string source = "fuzz/checkpoint.json";
  auto parse = [&](const std::string& text) { return CapsuleCheckpoint::parse(text, files.vertices, source); };
  ASSERT_NO_THROW(parse(files.checkpoint));
  const nlohmann::json seed = nlohmann::json::parse(files.checkpoint);
  const long n = inputs_per_reader(5000);
  std::mt19937_64 rng(20261202);
  Outcome out;
  for (long i = 0; i < n; ++i) {
    const std::string input = i % 2 == 0 ? mutate_file(files.checkpoint, rng) : mutate_structure(seed, rng);
    expect_accepted_or_error(input, source, parse, out, i);
    if (HasFatalFailure()) return;
  }
  EXPECT_GT(out.accepted, 0);
  EXPECT_GT(out.refused, 0);
  std::cout << "[ info ] " << n << " checkpoint inputs: " << out.accepted << " accepted, " << out.refused
            << " refused\n";
}

TEST(CapsuleReaderFuzz, EveryMutatedTimeSeriesIsAcceptedOrRefusedWithError) {
  const RunFiles files = run_files();
  const std::string source = "fuzz/timeseries.csv";
  auto parse = [&](const std::string& text) { return parse_time_series(text, source); };
  ASSERT_EQ(parse(files.series).size(), 2u);
  const long n = inputs_per_reader(25000);
  std::mt19937_64 rng(20261203);
  Outcome out;
  for (long i = 0; i < n; ++i) {
    expect_accepted_or_error(mutate_file(files.series, rng), source, parse, out, i);
    if (HasFatalFailure()) return;
  }
  EXPECT_GT(out.accepted, 0);
  EXPECT_GT(out.refused, 0);
  std::cout << "[ info ] " << n << " time-series inputs: " << out.accepted << " accepted, " << out.refused
            << " refused\n";
}

namespace {

std::string read_or_empty(const fs::path& p) {
  std::error_code ec;
  return fs::is_regular_file(p, ec) ? read_regular_file(p) : std::string();
}

}  // namespace

// A resume reads back checkpoint.json and timeseries.csv and checks them against each other and
// the folder. Seeded with the cases that were once accepted (issue 29: dt_next 0 or 1e308, a
// time after the last row, steps lowered, a side file naming the time series, an empty or
// shortened snapshot list, a garbage or 7-column kept row), which must be refused, then mutated
// further: every input is resumed (one step) or refused with bendlab::Error, and a refusal
// leaves both files as they were.
TEST(CapsuleReaderFuzz, EveryMutatedResumeIsResumedOrRefusedBeforeAnyChange) {
  const fs::path root = fs::temp_directory_path() / ("bendlab_resume_fuzz_" + std::to_string(::getpid()));
  fs::remove_all(root);
  fs::create_directories(root);
  MembraneParameters p;
  p.kS = ShearUnits::from(0.1, 0.0, std::nullopt).kS();
  auto membrane = std::make_shared<const MembraneModel>(sphere_mesh(MeshFamily::MT1, kLevel), p);
  CapsuleRunOptions o;
  o.folder = root / "base";
  o.t_end = 0.003;
  o.snapshot_every = 0.001;
  o.arguments = {{"solver", "bim"}, {"G", 0.1}, {"kappa_b_hat", 0.0}};
  {
    BimCapsuleSolver solver(membrane);
    ASSERT_TRUE(run_capsule(solver, o).finished);
  }
  const std::string checkpoint = read_regular_file(o.folder / "checkpoint.json");
  const std::string series = read_regular_file(o.folder / "timeseries.csv");
  const nlohmann::json seed = nlohmann::json::parse(checkpoint);
  const std::size_t row2 = series.find('\n', series.find('\n') + 1) + 1;
  const std::string after_row2 = series.substr(series.find('\n', row2) + 1);

  auto edited = [&](auto edit) {
    nlohmann::json j = seed;
    edit(j);
    return j.dump();
  };
  const std::vector<std::pair<std::string, std::string>> must_refuse = {
      {edited([](auto& j) { j["solver_state"]["dt_next"] = 0; }), series},
      {edited([](auto& j) { j["solver_state"]["dt_next"] = 1e308; }), series},
      {edited([](auto& j) {
         j["time"] = j["time"].template get<double>() + 0.0005;  // still before the resumed t_end
         j["snapshots"].back()[0] = j["time"];
       }),
       series},
      {edited([](auto& j) { j["steps"] = j["steps"].template get<int>() - 1; }), series},
      {edited([](auto& j) { j["side_files"] = {"timeseries.csv"}; }), series},
      {edited([](auto& j) { j["snapshots"] = nlohmann::json::array(); }), series},
      {edited([](auto& j) { j["snapshots"].erase(j["snapshots"].size() - 1); }), series},
      {checkpoint, series.substr(0, row2) + "garbage\n" + after_row2},
      {checkpoint, series.substr(0, row2) + "0.001,0.1,0.2,4,12,nan,0.5\n" + after_row2},
  };

  const fs::path work = root / "work";
  auto resume = [&](const std::string& cp, const std::string& ts) {
    fs::remove_all(work);
    fs::copy(o.folder, work);
    spit(work / "checkpoint.json", cp);
    spit(work / "timeseries.csv", ts);
    BimCapsuleSolver solver(membrane);
    CapsuleRunOptions r = o;
    r.folder = work;
    r.resume = true;
    r.t_end = 0.004;
    r.stop_after_steps = 1;
    run_capsule(solver, r);
  };
  for (std::size_t k = 0; k < must_refuse.size(); ++k) {
    EXPECT_THROW(resume(must_refuse[k].first, must_refuse[k].second), Error) << "seed " << k;
    EXPECT_EQ(read_or_empty(work / "timeseries.csv"), must_refuse[k].second) << "seed " << k;
    EXPECT_EQ(read_or_empty(work / "checkpoint.json"), must_refuse[k].first) << "seed " << k;
  }

  const long n = inputs_per_reader(5000) / 25;  // each input is a resume: 200 by default
  std::mt19937_64 rng(20261204);
  Outcome out;
  for (long i = 0; i < n; ++i) {
    const auto& [cp_seed, ts_seed] = must_refuse[rng() % must_refuse.size()];
    std::string cp = cp_seed, ts = ts_seed;
    switch (rng() % 3) {
      case 0: cp = mutate_structure(nlohmann::json::parse(cp_seed), rng); break;
      case 1: ts = mutate_file(ts_seed, rng); break;
      default: cp = checkpoint, ts = i % 2 == 0 ? series : mutate_file(series, rng); break;
    }
    try {
      resume(cp, ts);
      ++out.accepted;
    } catch (const Error& e) {
      ++out.refused;
      // A refusal comes before any change; only a run that failed while stepping has written.
      if (std::string(e.what()).find("the run failed after step") == std::string::npos) {
        ASSERT_EQ(read_or_empty(work / "timeseries.csv"), ts) << "input " << i << ": " << e.what();
        ASSERT_EQ(read_or_empty(work / "checkpoint.json"), cp) << "input " << i << ": " << e.what();
      }
    } catch (const std::exception& e) {
      FAIL() << "input " << i << ": not a bendlab::Error: " << e.what() << "\n" << cp.substr(0, 2000);
    }
  }
  EXPECT_GT(out.accepted, 0);
  EXPECT_GT(out.refused, 0);
  std::cout << "[ info ] " << n << " resumes: " << out.accepted << " resumed, " << out.refused << " refused\n";
  fs::remove_all(root);
}
