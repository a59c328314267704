// bendlab flow as a user meets it: refusals before work, the plain Poiseuille flow, the files of a
// run with cells, and a resume that ends as the uninterrupted run. Small spheres (42 vertices) in
// a 5 um tube keep it cheap; the physics of many red blood cells is in the tube study.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>
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

// The numbers of a CSV file's column.
std::vector<double> column(const std::string& csv, const std::string& name) {
  std::istringstream in(csv);
  std::string line, cell;
  std::getline(in, line);
  std::istringstream header(line);
  int index = -1;
  for (int k = 0; std::getline(header, cell, ','); ++k)
    if (cell == name) index = k;
  std::vector<double> v;
  if (index < 0) return v;
  while (std::getline(in, line)) {
    // Split at every comma: an empty field (an undefined value, NaN) may also be the last one.
    std::size_t begin = 0;
    for (int k = 0; k <= index; ++k) {
      const std::size_t comma = line.find(',', begin);
      cell = line.substr(begin, comma == std::string::npos ? std::string::npos : comma - begin);
      begin = comma == std::string::npos ? line.size() : comma + 1;
    }
    v.push_back(cell.empty() ? std::nan("") : std::stod(cell));
  }
  return v;
}

std::vector<double> checkpoint_positions(const fs::path& folder) {
  std::ifstream in(folder / "checkpoint.json");
  return nlohmann::json::parse(in).at("solver_state").at("positions_lattice").get<std::vector<double>>();
}
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
  expect_refused(run("flow --hematocrit 0 --method M --option degree=9" + tube), "degree", out);
  expect_refused(run("flow --hematocrit 0 --method none --bending-net-force remove" + tube), "--bending-net-force", out);
  expect_refused(run("flow --hematocrit 0 --bending-net-force drop" + tube), "--bending-net-force", out);
  // A lattice viscosity near 0 could not develop the cell-free flow in any run's time.
  expect_refused(run("flow --hematocrit 0 --tau 0.500001" + tube), "--tau 0.500001", out);
  // Step counts beyond what a run can count (they wrapped to 0 steps or a row every step), and a
  // run shorter than one step (no step, no sample: NaN profiles).
  auto small = [&](const std::string& from, const std::string& to) {
    std::string options = kSmallTube;
    options.replace(options.find(from), from.size(), to);
    return "flow --hematocrit 0" + options + " --out " + out.string();
  };
  expect_refused(run(small("--t-end 8e-6", "--t-end 1e30")), "--t-end 1e+30 s is", out);
  expect_refused(run(small("--t-end 8e-6", "--t-end 8e-6 --plasma-viscosity 1e30")), "--t-end", out);
  expect_refused(run(small("--sample-every 1e-6", "--sample-every 1e30")), "--sample-every", out);
  expect_refused(run(small("--t-end 8e-6", "--t-end 1e-320")), "shorter than one lattice step", out);
}

TEST_F(Cli, FlowTimeScaleIsTheDensityScaledRunAndRefusesAReynoldsNumberAboveItsBound) {
  // --time-scale S runs the lattice with S times the density: the very run of --plasma-density S rho
  // (its time series byte for byte), with S recorded in its identity and dt S times the unscaled.
  const fs::path scaled = dir / "scaled", dense = dir / "dense", plain = dir / "plain";
  CliRun r = run("flow --cells 2 --time-scale 4" + kSmallTube + " --out " + scaled.string());
  ASSERT_EQ(r.status, 0) << r.err;
  const auto s = nlohmann::json::parse(r.out);
  EXPECT_EQ(s.at("time_scale").get<double>(), 4.0);
  EXPECT_NE(r.err.find("time scale S = 4"), std::string::npos) << r.err;
  r = run("flow --cells 2 --plasma-density 4100" + kSmallTube + " --out " + dense.string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_FALSE(nlohmann::json::parse(r.out).contains("time_scale"));
  EXPECT_EQ(slurp(scaled / "timeseries.csv"), slurp(dense / "timeseries.csv"));
  EXPECT_EQ(slurp(scaled / "cells.csv"), slurp(dense / "cells.csv"));
  r = run("flow --cells 2" + kSmallTube + " --out " + plain.string());
  ASSERT_EQ(r.status, 0) << r.err;
  const auto p = nlohmann::json::parse(r.out);
  EXPECT_NEAR(s.at("dt_s").get<double>(), 4 * p.at("dt_s").get<double>(), 1e-12 * s.at("dt_s").get<double>());
  EXPECT_NEAR(s.at("reynolds").get<double>(), 4 * p.at("reynolds").get<double>(), 1e-12);
  // A resume must name the same S.
  r = run("flow --cells 2 --resume" + kSmallTube + " --out " + scaled.string());
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.err.find("time_scale"), std::string::npos) << r.err;
  // Refused: below 1, and where Re would pass its bound (here Re = 0.0043 unscaled: S = 250 gives 1.07,
  // at Mach 0.092, under the Mach bound).
  const fs::path out = dir / "r";
  expect_refused(run("flow --hematocrit 0 --time-scale 0.5" + kSmallTube + " --out " + out.string()), "--time-scale 0.5",
                 out);
  expect_refused(run("flow --hematocrit 0 --time-scale 250" + kSmallTube + " --out " + out.string()),
                 "--time-scale 250: the Reynolds number", out);
}

TEST_F(Cli, FlowMembraneEveryIsRecordedResumesAsTheUninterruptedRunAndRefusesZero) {
  // --membrane-every 4: said on stderr, in the run's identity and summary; a run stopped and
  // resumed from its checkpoint ends as the uninterrupted one (reports fall on multiples of 4, where
  // the held forces are renewed).
  const fs::path whole = dir / "whole", parts = dir / "parts", out = dir / "r";
  CliRun r = run("flow --cells 2 --membrane-every 4" + kSmallTube + " --out " + whole.string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(r.out).at("membrane_every").get<int>(), 4);
  EXPECT_NE(r.err.find("membrane forces every 4 lattice steps"), std::string::npos) << r.err;
  r = run("flow --cells 2 --membrane-every 4 --stop-after-steps 5" + kSmallTube + " --out " + parts.string());
  ASSERT_EQ(r.status, 0) << r.err;
  r = run("flow --cells 2 --membrane-every 4 --resume" + kSmallTube + " --out " + parts.string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(slurp(parts / "timeseries.csv"), slurp(whole / "timeseries.csv"));
  EXPECT_EQ(checkpoint_positions(parts), checkpoint_positions(whole));
  // Every step is the default, and a resume must name the same N.
  r = run("flow --cells 2 --resume" + kSmallTube + " --out " + whole.string());
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.err.find("membrane_every"), std::string::npos) << r.err;
  expect_refused(run("flow --hematocrit 0 --membrane-every 0" + kSmallTube + " --out " + out.string()), "--membrane-every",
                 out);
}

TEST_F(Cli, FlowWritesNoNonFiniteNumber) {
  // Without cells there is no cell-free layer: an empty field, not "nan".
  for (const char* cells : {"--cells 0", "--hematocrit 0"}) {
    const fs::path out = dir / (std::string("r") + cells[2]);
    const CliRun r = run(std::string("flow ") + cells + kSmallTube + " --out " + out.string());
    ASSERT_EQ(r.status, 0) << r.err;
    for (const char* file : {"timeseries.csv", "profiles.csv", "summary.json"}) {
      const std::string text = slurp(out / file);
      EXPECT_EQ(text.find("nan"), std::string::npos) << file << ":\n" << text;
      EXPECT_EQ(text.find("inf"), std::string::npos) << file << ":\n" << text;
    }
    const std::vector<double> layer = column(slurp(out / "timeseries.csv"), "cell_free_layer_um");
    ASSERT_FALSE(layer.empty());
    for (double v : layer) EXPECT_TRUE(std::isnan(v));
  }
}

TEST_F(Cli, FlowTakesANewFolderWithATrailingSlash) {
  const CliRun r = run("flow --hematocrit 0" + kSmallTube + " --out " + (dir / "r").string() + "/");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(fs::exists(dir / "r" / "summary.json"));
}

TEST_F(Cli, FlowRemovesTheBendingNetForceByDefaultAndKeepsItWhenAsked) {
  // By default the spheres' Method C force loses its net force and torque (momentum-conserving
  // bending); --bending-net-force keep keeps them, and the run's identity says which (a resume with
  // the other is refused). The run says which it uses.
  const fs::path removed = dir / "remove", kept = dir / "keep";
  CliRun r = run("flow --cells 2" + kSmallTube + " --out " + removed.string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(nlohmann::json::parse(r.out).at("bending_without_net_force").get<bool>());
  EXPECT_NE(r.err.find("net force and torque removed on each cell (the default"), std::string::npos) << r.err;
  r = run("flow --cells 2 --bending-net-force remove" + kSmallTube + " --out " + (dir / "explicit").string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(checkpoint_positions(removed), checkpoint_positions(dir / "explicit"));
  r = run("flow --cells 2 --bending-net-force keep" + kSmallTube + " --out " + kept.string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_FALSE(nlohmann::json::parse(r.out).contains("bending_without_net_force"));
  EXPECT_NE(r.err.find("net force and torque kept"), std::string::npos) << r.err;
  EXPECT_NE(checkpoint_positions(removed), checkpoint_positions(kept));
  r = run("flow --cells 2 --resume" + kSmallTube + " --out " + kept.string());
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.err.find("bending_without_net_force"), std::string::npos) << r.err;
  // Without a bending force there is nothing to remove: the default asks for nothing.
  r = run("flow --cells 2 --method none --bending-modulus 0" + kSmallTube + " --out " + (dir / "none").string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_FALSE(nlohmann::json::parse(r.out).contains("bending_without_net_force"));
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

TEST_F(Cli, FlowStoppedAtAnyReportAndResumedWritesEveryFileOfTheUninterruptedRun) {
  // 8 reports, a snapshot and checkpoint after the 4th and the 8th. A stop after the first
  // snapshot resumes from it: its later snapshots must come at the uninterrupted run's steps, not
  // one interval after the snapshot's own (later) time.
  const fs::path full = dir / "full";
  CliRun r = run("flow --cells 2" + kSmallTube + " --out " + full.string());
  ASSERT_EQ(r.status, 0) << r.err;
  for (int k : {1, 4, 5, 7}) {
    SCOPED_TRACE(k);
    const fs::path parts = dir / ("parts" + std::to_string(k));
    r = run("flow --cells 2 --stop-after-steps " + std::to_string(k) + kSmallTube + " --out " + parts.string());
    ASSERT_EQ(r.status, 0) << r.err;
    ASSERT_FALSE(fs::exists(parts / "summary.json"));
    r = run("flow --cells 2 --resume" + kSmallTube + " --out " + parts.string());
    ASSERT_EQ(r.status, 0) << r.err;
    expect_same_run_files(full, parts);
  }
}

TEST_F(Cli, FlowStoppedBetweenItsFinalCheckpointAndItsSummaryIsCompletedByAResume) {
  // The final checkpoint lies at the last lattice step, a little past --t-end: a resume to the
  // same --t-end takes no step and writes the summary (as after a kill, or a full disk, there).
  const fs::path full = dir / "full", cut = dir / "cut";
  CliRun r = run("flow --cells 2" + kSmallTube + " --out " + full.string());
  ASSERT_EQ(r.status, 0) << r.err;
  r = run("flow --cells 2" + kSmallTube + " --out " + cut.string());
  ASSERT_EQ(r.status, 0) << r.err;
  fs::remove(cut / "summary.json");
  fs::remove(cut / "timing.json");
  r = run("flow --cells 2 --resume" + kSmallTube + " --out " + cut.string());
  ASSERT_EQ(r.status, 0) << r.err;
  expect_same_run_files(full, cut);
  // An earlier end than the run reached is still refused.
  std::string earlier = kSmallTube;
  earlier.replace(earlier.find("--t-end 8e-6"), 12, "--t-end 6e-6");
  r = run("flow --cells 2 --resume" + earlier + " --out " + cut.string());
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.err.find("before the checkpoint"), std::string::npos) << r.err;
}

TEST_F(Cli, FlowShearWithoutCellsHasThePlasmaViscosity) {
  // The walls' linear shear flow is a steady state of the lattice, and its wall stress is eta gamma.
  const CliRun r = run("flow --geometry shear --height 4 --width 3 --length 3 --shear-rate 2000 --hematocrit 0 "
                       "--t-end 4e-6 --sample-every 1e-6 --out " + (dir / "r").string());
  ASSERT_EQ(r.status, 0) << r.err;
  const auto s = nlohmann::json::parse(r.out);
  EXPECT_NEAR(s.at("apparent_viscosity").at("mean").get<double>(), 1.0, 1e-12);
  EXPECT_NEAR(s.at("mean_velocity_um_s").at("mean").get<double>(), 0.0, 1e-9);
  EXPECT_TRUE(s.at("discharge_hematocrit").at("mean").is_null());  // no net flux to discharge
  EXPECT_NEAR(s.at("shear_rate_1_s").get<double>(), 2000, 1e-9);
  expect_refused(run("flow --geometry shear --height 4 --width 3 --length 3 --pseudo-shear-rate 100 --hematocrit 0 "
                     "--out " + (dir / "q").string()),
                 "--shear-rate", dir / "q");
  expect_refused(run("flow --geometry shear --height 4 --width 3 --length 3 --hematocrit 0 --out " +
                     (dir / "q").string()),
                 "--shear-rate", dir / "q");
  expect_refused(run("flow --geometry shear --height 4 --width 3 --length 3 --shear-rate 1e9 --hematocrit 0 --out " +
                     (dir / "q").string()),
                 "Mach", dir / "q");
}

// `shear --solver lbm` is the shear box of `flow` with one cell: the same lattice, capsule,
// membrane and steps, given once in the shear command's units (R = mu = gamma = 1, G, kB_hat)
// and once in physical ones. The runs differ only in the units the membrane's arithmetic is done
// in (the shear command's in units of R, scaled to lattice forces afterwards; flow's in lattice
// units), which rounds differently, by about 1e-16 relative per step: D and every vertex agree to
// 1e-12, not bit for bit.
TEST_F(Cli, FlowShearWithOneCellIsTheShearCommandsLatticeRun) {
  const double R = 3, nz = 9, Re = 0.2, G = 0.1, kb_hat = 0.01, t_end = 0.305, sample = 0.02;  // gamma t
  const double eta = 1.2e-3, rho = 1025, dx = 0.5e-6, nu_lattice = 1.0 / 6;                      // flow's defaults
  const double gamma_lattice = 2 * (Re * nu_lattice / R) / nz, dt = nu_lattice * dx * dx / (eta / rho);
  const double gamma = gamma_lattice / dt, radius = R * dx;
  const double G_s = eta * gamma * radius / (3 * G);  // kS = 3 G_s = eta gamma R / G
  const double kappa_b = kb_hat * radius * radius * 3 * G_s;
  const fs::path a = dir / "shear", b = dir / "flow";
  CliRun r = run(fmt::format("shear --solver lbm --shape sphere --mesh mt1:80 --membrane neo-hookean --G {} "
                             "--kappa-b-hat {} --method C --radius-lu {} --box 3 3 3 --reynolds {} --t-end {} "
                             "--sample-every {} --snapshot-every 0.15 --no-plot --out {}",
                             G, kb_hat, R, Re, t_end, sample, a.string()));
  ASSERT_EQ(r.status, 0) << r.err;
  r = run(fmt::format("flow --geometry shear --height 4.5 --width 4.5 --length 4.5 --dx 0.5 --shear-rate {:.17g} "
                      "--cells 1 --cell sphere --cell-radius {:.17g} --mesh mt1:80 --membrane neo-hookean "
                      "--shear-modulus {:.17g} --bending-modulus {:.17g} --method C --bending-net-force keep --t-end {:.17g} "
                      "--sample-every {:.17g} --snapshot-every {:.17g} --out {}",
                      gamma, radius * 1e6, G_s, kappa_b, t_end / gamma, sample / gamma, 0.15 / gamma, b.string()));
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string series = slurp(a / "timeseries.csv"), cells = slurp(b / "cells.csv");
  const std::vector<double> D_shear = column(series, "D"), D_flow = column(cells, "D");
  const std::vector<double> angle_shear = column(series, "axis_angle"), angle_flow = column(cells, "axis_angle_deg");
  ASSERT_GE(D_shear.size(), 10u);
  ASSERT_EQ(D_shear.size(), D_flow.size());
  for (std::size_t k = 0; k < D_shear.size(); ++k) {
    EXPECT_NEAR(D_flow[k], D_shear[k], 1e-12) << "row " << k;
    // The shear command's axis angle is the short axis's in the shear plane from e_z towards e_x
    // (unwrapped, radians); flow's is its angle to the flow direction e_x (degrees, 0 to 90).
    EXPECT_NEAR(std::abs(std::cos(angle_flow[k] * M_PI / 180)), std::abs(std::sin(angle_shear[k])), 1e-9) << k;
  }
  EXPECT_GT(D_shear.back(), 0.01);  // the capsule did deform
  const std::vector<double> X_shear = checkpoint_positions(a), X_flow = checkpoint_positions(b);
  ASSERT_EQ(X_shear.size(), X_flow.size());
  for (std::size_t k = 0; k < X_shear.size(); ++k) EXPECT_NEAR(X_flow[k], X_shear[k], 1e-12 * R) << k;
}
