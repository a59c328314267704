// bendlab stretch as a user meets it: refusals before work (one line, non-zero exit, no folder),
// the files of a run on the 162-vertex red blood cell, and the run folder's rules. The physics is
// in tests/flow/test_optical_stretch.cpp.
#include <nlohmann/json.hpp>

#include "cli/cli_fixture.hpp"

using bendlab_cli_test::Cli;
using bendlab_cli_test::CliRun;
namespace fs = std::filesystem;

namespace {
const std::string kCoarse = " --mesh mt1:320 --no-plots";

std::string fmt_shape(std::size_t k) {
  std::string name = std::to_string(k);
  return "shape_" + std::string(3 - std::min<std::size_t>(3, name.size()), '0') + name + ".vtp";
}

std::vector<std::vector<double>> read_csv(const std::string& text, std::string& header) {
  std::istringstream in(text);
  std::getline(in, header);
  std::vector<std::vector<double>> rows;
  for (std::string line; std::getline(in, line);) {
    std::vector<double> row;
    std::istringstream cells(line);
    for (std::string cell; std::getline(cells, cell, ',');) row.push_back(std::stod(cell));
    rows.push_back(row);
  }
  return rows;
}
}  // namespace

TEST_F(Cli, StretchRefusesBadInputWithOneLineBeforeWork) {
  const fs::path out = dir / "r";
  const std::string o = kCoarse + " --out " + out.string();
  expect_refused(run("stretch --forces 0,-5" + o), "--forces", out);
  expect_refused(run("stretch --forces 0,nan" + o), "--forces", out);
  expect_refused(run("stretch --forces 0,inf" + o), "--forces", out);
  expect_refused(run("stretch --forces 0,ten" + o), "--forces", out);
  expect_refused(run("stretch --fraction 0.001" + o), "selects no vertex", out);
  expect_refused(run("stretch --fraction 0.6" + o), "--fraction", out);
  expect_refused(run("stretch --fraction -0.02" + o), "--fraction", out);
  expect_refused(run("stretch --shear-modulus 0" + o), "--shear-modulus", out);
  expect_refused(run("stretch --shear-modulus nan" + o), "--shear-modulus", out);
  expect_refused(run("stretch --bending-modulus -1e-19" + o), "--bending-modulus", out);
  expect_refused(run("stretch --bending-modulus inf" + o), "--bending-modulus", out);
  expect_refused(run("stretch --skalak-c -1" + o), "--skalak-c", out);
  expect_refused(run("stretch --tolerance 0" + o), "--tolerance", out);
  expect_refused(run("stretch --max-iterations 0" + o), "--max-iterations", out);
  expect_refused(run("stretch --law hooke" + o), "--law", out);
  expect_refused(run("stretch --method Q" + o), "--method", out);
  expect_refused(run("stretch --method C --option rings=2" + o), "rings", out);
  expect_refused(run("stretch --mesh mt1:7 --no-plots --out " + out.string()), "mt1:7", out);
  expect_refused(run("stretch" + kCoarse + " --out " + (dir / "missing" / "r").string()), "does not exist",
                 dir / "missing");
  // Every entry of the list counts: an empty one is refused, not dropped.
  for (const char* forces : {"1,,2", "1,2,", ",1"})
    expect_refused(run(std::vector<std::string>{"stretch", "--forces", forces, "--mesh", "mt1:320", "--no-plots",
                                                "--out", out.string()}),
                   "--forces", out);
  expect_refused(run(std::vector<std::string>{"stretch", "--forces", "", "--out", out.string()}), "--forces", out);
  // Moduli whose forces overflow double precision are refused by name, before the folder exists.
  expect_refused(run("stretch --mesh mt1:80 --forces 0,10 --skalak-c 1e308 --no-plots --out " + out.string()),
                 "--skalak-c 1e+308", out);
}

TEST_F(Cli, StretchWritesNoNonFiniteNumberWhenARelaxationFails) {
  // 1e308 pN: the residual is a length of 1e308 pN (not an infinite one); the relaxation fails in
  // its budget, the run says so and exits non-zero, and stretch.csv holds only numbers.
  const fs::path out = dir / "r";
  const CliRun r = run("stretch --mesh mt1:80 --forces 1e308 --max-iterations 100 --no-plots --out " + out.string());
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.err.find("did not reach equilibrium"), std::string::npos) << r.err;
  const std::string csv = slurp(out / "stretch.csv");
  ASSERT_FALSE(csv.empty());
  EXPECT_EQ(csv.find("inf"), std::string::npos) << csv;
  EXPECT_EQ(csv.find("nan"), std::string::npos) << csv;
}

TEST_F(Cli, StretchTakesANewFolderWithATrailingSlash) {
  const CliRun r = run("stretch --mesh mt1:80 --forces 0 --no-plots --out " + (dir / "r").string() + "/");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(fs::exists(dir / "r" / "stretch.csv"));
}

TEST_F(Cli, StretchWritesItsTablesShapesAndSummary) {
  const fs::path out = dir / "r";
  const CliRun r = run("stretch --forces 0,30,60" + kCoarse + " --out " + out.string());
  ASSERT_EQ(r.status, 0) << r.err;
  // A progress line per force.
  for (const char* f : {"F = 0 pN", "F = 30 pN", "F = 60 pN"}) EXPECT_NE(r.err.find(f), std::string::npos) << r.err;
  std::string header;
  const auto rows = read_csv(slurp(out / "stretch.csv"), header);
  EXPECT_EQ(header.rfind("force_pN,axial_diameter_um,transverse_diameter_um,iterations,residual_pN,area_change,"
                         "volume_change",
                         0),
            0u)
      << header;
  ASSERT_EQ(rows.size(), 3u);
  const auto s = nlohmann::json::parse(slurp(out / "summary.json"));
  const double tolerance = s.at("tolerance_pN").get<double>();
  EXPECT_TRUE(s.at("converged").get<bool>());
  EXPECT_EQ(s.at("method").get<std::string>(), "C");
  EXPECT_EQ(s.at("elastic_law").get<std::string>(), "skalak");
  EXPECT_EQ(s.at("points").size(), 3u);
  for (std::size_t k = 0; k < rows.size(); ++k) {
    EXPECT_EQ(rows[k][0], std::vector<double>({0, 30, 60})[k]);
    EXPECT_LT(rows[k][4], tolerance) << k;  // residual
    EXPECT_EQ(s.at("points")[k].at("applied_force_sum_pN").get<double>(), 0.0);
    EXPECT_TRUE(fs::exists(out / fmt_shape(k))) << k;
    if (k > 0) {
      EXPECT_GT(rows[k][1], rows[k - 1][1]) << k;  // axial grows
      EXPECT_LT(rows[k][2], rows[k - 1][2]) << k;  // transverse shrinks
    }
  }
  EXPECT_TRUE(fs::exists(out / "shapes.pvd"));
  // The folder now holds a run: refused without --overwrite, its files untouched; replaced with it.
  const std::string before = slurp(out / "stretch.csv");
  const CliRun again = run("stretch --forces 0" + kCoarse + " --out " + out.string());
  EXPECT_NE(again.status, 0);
  EXPECT_NE(again.err.find("not empty"), std::string::npos) << again.err;
  EXPECT_EQ(slurp(out / "stretch.csv"), before);
  write(out / "notes.txt", "mine");
  const CliRun over = run("stretch --forces 0" + kCoarse + " --overwrite --out " + out.string());
  ASSERT_EQ(over.status, 0) << over.err;
  EXPECT_FALSE(fs::exists(out / "shape_001.vtp"));  // the earlier run's
  EXPECT_EQ(slurp(out / "notes.txt"), "mine");       // not a run's file
}

TEST_F(Cli, StretchThatCannotConvergeFailsWithOneLineAndKeepsWhatItReached) {
  const fs::path out = dir / "r";
  const CliRun r = run("stretch --forces 0,50 --max-iterations 3" + kCoarse + " --out " + out.string());
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.err.find("bendlab: error: stretch: F = 0 pN did not reach equilibrium"), std::string::npos) << r.err;
  const auto s = nlohmann::json::parse(slurp(out / "summary.json"));
  EXPECT_FALSE(s.at("converged").get<bool>());
  EXPECT_EQ(s.at("failed_at_pN").get<double>(), 0.0);
}

TEST_F(Cli, StretchHelpNamesEveryOption) {
  const CliRun r = run("stretch --help");
  ASSERT_EQ(r.status, 0);
  for (const char* o : {"--forces", "--fraction", "--tolerance", "--max-iterations", "--mesh", "--method", "--option",
                        "--law", "--shear-modulus", "--skalak-c", "--bending-modulus", "--volume-ratio", "--out",
                        "--overwrite", "--plot-script", "--python"})
    EXPECT_NE(r.out.find(o), std::string::npos) << o;
}
