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

namespace fs = std::filesystem;
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
