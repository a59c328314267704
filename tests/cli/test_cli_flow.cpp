// bendlab flow as a user meets it: refusals before work, the plain Poiseuille flow, the files of a
// run with cells, and a resume that ends as the uninterrupted run. Small spheres (42 vertices) in
// a 5 um tube keep it cheap; the physics of many red blood cells is in the tube study.
#include <algorithm>
#include <nlohmann/json.hpp>

#include "cli/cli_fixture.hpp"

using bendlab_cli_test::Cli;
using bendlab_cli_test::CliRun;
namespace fs = std::filesystem;

namespace {
// Two spheres of radius 1.2 um (mt1:80, edges about 0.5 um = 1 dx) in a tube 5 um across, 5 um
// long: a lattice of 10 x 14 x 14 nodes; dt = 3.6e-8 s at tau 1, so 8e-6 s is 225 steps.
const std::string kSmallTube =
    " --diameter 5 --length 5 --dx 0.5 --pseudo-shear-rate 200 --cell sphere --cell-radius 1.2 --mesh mt1:80 "
    "--sample-every 1e-6 --snapshot-every 4e-6 --t-end 8e-6";
}  // namespace

TEST_F(Cli, FlowRefusesBadInputWithOneLineBeforeWork) {
  const fs::path out = dir / "r";
  const std::string tube = " --diameter 10 --length 10 --pseudo-shear-rate 100 --out " + out.string();
  expect_refused(run("flow --hematocrit -0.1" + tube), "--hematocrit -0.1", out);
  expect_refused(run("flow --hematocrit 0.9" + tube), "cannot place", out);
  expect_refused(run("flow --hematocrit 0.1 --diameter 3 --length 10 --pseudo-shear-rate 100 --out " + out.string()),
                 "--diameter 3 um is narrower than the cell", out);
  expect_refused(run("flow --hematocrit 0 --tau 0.5" + tube), "tau", out);
  expect_refused(run("flow --hematocrit 0 --diameter 10 --length 10 --pseudo-shear-rate 1e7 --out " + out.string()),
                 "Mach", out);
  expect_refused(run("flow --geometry pipe --hematocrit 0" + tube), "--geometry", out);
  expect_refused(run("flow --geometry channel --hematocrit 0 --height 10 --length 10 --pseudo-shear-rate 100 --out " +
                     out.string()),
                 "--width", out);
  expect_refused(run("flow --hematocrit 0 --diameter 10 --length 10 --out " + out.string()), "driving", out);
}

TEST_F(Cli, FlowWarnsOfAMeshCoarserThanTheLattice) {
  // mt1:20 on a sphere of radius 1.2 um: edges of about 1.3 um, 2.6 dx.
  const CliRun r = run("flow --cells 1 --cell sphere --cell-radius 1.2 --mesh mt1:20 --diameter 5 --length 5 "
                       "--pseudo-shear-rate 100 --t-end 1e-7 --sample-every 1e-7 --out " + (dir / "r").string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("warning"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("dx"), std::string::npos) << r.err;
}

TEST_F(Cli, FlowWithoutCellsIsTheCellFreeFlow) {
  // Q0 is the relaxed cell-free flow's own rate: without cells eta_app / eta is 1 to the
  // relaxation's tolerance (1e-9 per 100 steps), and the mean velocity is the pseudo-shear rate
  // times D to the section's discretisation (the nodes' square cells against pi D^2 / 4).
  const CliRun r = run("flow --hematocrit 0" + kSmallTube + " --out " + (dir / "r").string());
  ASSERT_EQ(r.status, 0) << r.err;
  const auto s = nlohmann::json::parse(r.out);
  EXPECT_NEAR(s.at("apparent_viscosity").at("mean").get<double>(), 1.0, 1e-7);
  EXPECT_NEAR(s.at("mean_velocity_um_s").at("mean").get<double>(), 200 * 5, 0.01 * 200 * 5);
  EXPECT_EQ(s.at("tube_hematocrit").at("mean").get<double>(), 0.0);
  EXPECT_TRUE(s.at("cell_free_layer_um").at("mean").is_null());
  EXPECT_EQ(s.at("cells").get<int>(), 0);
}

TEST_F(Cli, FlowStoppedAndResumedEqualsUninterrupted) {
  const fs::path full = dir / "full", parts = dir / "parts";
  CliRun r = run("flow --cells 2" + kSmallTube + " --out " + full.string());
  ASSERT_EQ(r.status, 0) << r.err;
  const auto s = nlohmann::json::parse(r.out);
  for (const char* key : {"apparent_viscosity", "tube_hematocrit", "discharge_hematocrit", "cell_free_layer_um",
                          "mean_velocity_um_s"}) {
    ASSERT_TRUE(s.contains(key)) << key;
    EXPECT_TRUE(s.at(key).at("mean").is_number()) << key;
    EXPECT_TRUE(s.at(key).at("standard_error").is_number()) << key;
  }
  EXPECT_EQ(s.at("cells").get<int>(), 2);
  // A row per cell per report.
  const std::string series = slurp(full / "timeseries.csv"), cells = slurp(full / "cells.csv");
  EXPECT_EQ(std::count(cells.begin(), cells.end(), '\n') - 1, 2 * (std::count(series.begin(), series.end(), '\n') - 1));
  EXPECT_TRUE(fs::exists(full / "profiles.csv"));
  EXPECT_TRUE(fs::exists(full / "snapshot_00002.vtp"));
  // The fluid slice beside each snapshot: 10 x 14 nodes of the plane y = 0.
  const std::string slice = slurp(full / "fluid_00002.vtk");
  EXPECT_NE(slice.find("DIMENSIONS 10 1 14"), std::string::npos) << slice.substr(0, 300);
  EXPECT_NE(slice.find("POINT_DATA 140"), std::string::npos);

  r = run("flow --cells 2 --stop-after-steps 5" + kSmallTube + " --out " + parts.string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_FALSE(fs::exists(parts / "summary.json"));
  r = run("flow --cells 2 --resume" + kSmallTube + " --out " + parts.string());
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* file : {"timeseries.csv", "cells.csv", "profiles.csv", "summary.json", "shapes.pvd",
                           "snapshot_00001.vtp", "snapshot_00002.vtp", "fluid_00001.vtk", "fluid_00002.vtk"})
    EXPECT_EQ(slurp(parts / file), slurp(full / file)) << file;
  // Another seed is another run.
  r = run("flow --cells 2 --resume --seed 7" + kSmallTube + " --out " + parts.string());
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.err.find("seed"), std::string::npos) << r.err;
}
