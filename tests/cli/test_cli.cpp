// The command line as a user meets it: exit codes, one-line errors, files whole or absent.
// bendlab is started with an argument vector (posix_spawn, no shell), its stdout and stderr
// redirected to files, so that any byte a user may put in a file name reaches it unchanged.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <spawn.h>
#include <sys/file.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <vector>

#include "cli/cli_fixture.hpp"

namespace fs = std::filesystem;

using bendlab_cli_test::Cli;
using bendlab_cli_test::CliRun;

namespace {

// A closed tetrahedron with outward faces, and variants with one defect each.
const std::string kTetraVertices = "0 0 0\n1 0 0\n0 1 0\n0 0 1\n";
const std::string kTetraFaces = "3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";

std::string off(const std::string& vertices, const std::string& faces, int nv, int nf) {
  return "OFF\n" + std::to_string(nv) + " " + std::to_string(nf) + " 0\n" + vertices + faces;
}

}  // namespace

TEST_F(Cli, HelpOnEverySubcommand) {
  for (const char* sub : {"mesh", "shape", "forces", "rbc", "shear"}) {
    const CliRun r = run(std::string(sub) + " --help");
    EXPECT_EQ(r.status, 0) << sub;
    EXPECT_NE(r.out.find("--out"), std::string::npos) << sub << ": " << r.out;
  }
}

TEST_F(Cli, MeshPrintsSummaryForEveryFormat) {
  for (const char* ext : {"off", "ply", "obj", "vtp"}) {
    const fs::path out = dir / (std::string("m.") + ext);
    const CliRun r = run("mesh --family mt1 --level 2 --shape rbc --out " + out.string());
    ASSERT_EQ(r.status, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["triangles"], 320);
    EXPECT_EQ(j["vertices"], 162);
    EXPECT_EQ(j["min_valence"], 5);
    EXPECT_EQ(j["max_valence"], 6);
    EXPECT_GT(j["mean_edge_length"].get<double>(), 0);
    EXPECT_GT(j["min_angle_deg"].get<double>(), 0);
    EXPECT_TRUE(fs::exists(out));
  }
  const CliRun octa = run("mesh --family octa --level 3 --out " + (dir / "o.off").string());
  ASSERT_EQ(octa.status, 0) << octa.err;
  EXPECT_EQ(nlohmann::json::parse(octa.out)["triangles"], 512);
}

TEST_F(Cli, ShapeAndForcesWriteTheDocumentedColumns) {
  const fs::path mesh = dir / "rbc.off";
  ASSERT_EQ(run("mesh --family mt1 --level 2 --shape rbc --out " + mesh.string()).status, 0);
  const fs::path shape = dir / "shape.csv";
  CliRun r = run("shape --mesh " + mesh.string() + " --shape rbc --out " + shape.string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(slurp(shape).rfind("x,y,z,nx,ny,nz,H,K,lapH,fx,fy,fz", 0), 0u);
  const auto methods = nlohmann::json::parse(run("methods --json").out);
  ASSERT_GE(methods.size(), 6u);
  for (const auto& entry : methods) {
    const std::string m = entry["name"];
    const fs::path forces = dir / ("forces_" + m + ".csv");
    r = run("forces --mesh " + mesh.string() + " --method " + m + " --shape rbc --out " + forces.string());
    ASSERT_EQ(r.status, 0) << m << ": " << r.err;
    const std::string text = slurp(forces);
    EXPECT_EQ(text.rfind("x,y,z,nx,ny,nz,H,K,lapH,fx,fy,fz,Fx,Fy,Fz,area,", 0), 0u) << m;
    EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 163) << m;  // header + 162 vertices
  }
}

TEST_F(Cli, MethodsListsTheRegistryAsTableAndJson) {
  const CliRun r = run("methods --json");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  std::vector<std::string> names;
  for (const auto& m : j) {
    names.push_back(m["name"]);
    EXPECT_FALSE(m["description"].get<std::string>().empty());
    EXPECT_TRUE(m["options"].is_array());
    for (const char* key : {"has_energy", "defines_normal", "defines_H", "defines_K", "defines_lapH",
                            "needs_admissible_mesh", "cost"})
      EXPECT_TRUE(m["capabilities"].contains(key)) << key;
  }
  EXPECT_EQ(names, (std::vector<std::string>{"A", "B", "C", "D", "E", "ED", "S", "J", "M"}));
  EXPECT_TRUE(j[6]["capabilities"]["needs_admissible_mesh"].get<bool>());
  EXPECT_TRUE(j[0]["capabilities"]["has_energy"].get<bool>());
  EXPECT_FALSE(j[2]["capabilities"]["has_energy"].get<bool>());
  EXPECT_EQ(j[3]["capabilities"]["cost"], "O(N)");
  EXPECT_EQ(j[3]["options"][0]["name"], "neighbours");
  EXPECT_EQ(j[3]["options"][1]["name"], "kernel_cutoff");
  EXPECT_EQ(j[0]["options"][0]["name"], "small_angle");
  EXPECT_EQ(j[0]["options"][0]["type"], "bool");
  const auto& rings = j[4]["options"][0];
  EXPECT_EQ(rings["name"], "rings");
  EXPECT_EQ(rings["type"], "int");
  EXPECT_EQ(rings["default"], "1");
  EXPECT_EQ(rings["min"], 1);
  EXPECT_EQ(rings["max"], 3);
  EXPECT_EQ(j[5]["options"], j[4]["options"]);
  // The table: one line per method (and per option), every name and description in it.
  const CliRun t = run("methods");
  ASSERT_EQ(t.status, 0) << t.err;
  for (const auto& m : j) {
    EXPECT_NE(t.out.find("\n" + m["name"].get<std::string>() + " "), std::string::npos) << t.out;
    EXPECT_NE(t.out.find(m["description"].get<std::string>()), std::string::npos) << t.out;
  }
  EXPECT_NE(t.out.find("--option rings=1"), std::string::npos) << t.out;
  // forces --help names every method.
  const CliRun help = run("forces --help");
  for (const auto& m : j) EXPECT_NE(help.out.find(m["description"].get<std::string>()), std::string::npos);
}

TEST_F(Cli, ForcesTakesMethodOptionsByName) {
  const fs::path mesh = dir / "s.off";
  ASSERT_EQ(run("mesh --family mt1 --level 1 --out " + mesh.string()).status, 0);
  const fs::path a = dir / "a.csv", b = dir / "b.csv", out = dir / "c.csv";
  ASSERT_EQ(run("forces --mesh " + mesh.string() + " --method E --rings 2 --out " + a.string()).status, 0);
  ASSERT_EQ(run("forces --mesh " + mesh.string() + " --method E --option rings=2 --out " + b.string()).status, 0);
  EXPECT_EQ(slurp(a), slurp(b));
  expect_refused(run("forces --mesh " + mesh.string() + " --method E --option rings=4 --out " + out.string()),
                 "rings", out);
  expect_refused(run("forces --mesh " + mesh.string() + " --method C --option bogus=1 --out " + out.string()),
                 "'bogus'", out);
  expect_refused(run("forces --mesh " + mesh.string() + " --method E --rings 2 --option rings=3 --out " +
                     out.string()), "twice", out);
  expect_refused(run("forces --mesh " + mesh.string() + " --method E --option rings --out " + out.string()),
                 "key=value", out);
}

TEST_F(Cli, RefusesBadMeshesWithOneLineNamingTheProblem) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"index out of range", off(kTetraVertices, "3 0 2 1\n3 0 1 3\n3 0 3 9\n3 1 2 3\n", 4, 4)},
      {"repeated index", off(kTetraVertices, "3 0 2 1\n3 0 1 1\n3 0 3 2\n3 1 2 3\n", 4, 4)},
      {"zero-area triangle", off("0 0 0\n1 0 0\n0 1 0\n0.5 0.5 0\n", kTetraFaces, 4, 4)},
      {"non-finite coordinate", off("0 0 0\n1 0 0\n0 1 0\n0 0 nan\n", kTetraFaces, 4, 4)},
      {"boundary edge", off(kTetraVertices, "3 0 2 1\n3 0 1 3\n3 0 3 2\n", 4, 3)},
      {"inconsistent orientation", off(kTetraVertices, "3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 3 2\n", 4, 4)},
      {"inward orientation", off(kTetraVertices, "3 0 1 2\n3 0 3 1\n3 0 2 3\n3 1 3 2\n", 4, 4)},
      {"unreferenced vertex", off(kTetraVertices + "5 5 5\n", kTetraFaces, 5, 4)},
      {"non-manifold edge",
       off(kTetraVertices + "0 -1 0\n0 0 -1\n", kTetraFaces + "3 0 1 4\n3 0 4 5\n3 0 5 1\n3 1 5 4\n", 6, 8)},
      {"non-manifold vertex",
       off(kTetraVertices + "-1 0 0\n0 -1 0\n0 0 -1\n", kTetraFaces + "3 0 5 4\n3 0 4 6\n3 0 6 5\n3 4 5 6\n", 7, 8)},
  };
  for (const auto& [problem, text] : cases) {
    const fs::path in = dir / "bad.off", out = dir / "out.csv";
    write(in, text);
    expect_refused(run("shape --mesh " + in.string() + " --shape sphere --out " + out.string()), problem, out);
    expect_refused(run("forces --mesh " + in.string() + " --method C --out " + out.string()), problem, out);
  }
}

TEST_F(Cli, MethodSRefusesAMeshWithTwoExtraordinaryVerticesInATriangle) {
  // The bare icosahedron and octahedron: every triangle has three vertices of valence != 6.
  for (const std::string family : {"mt1", "octa"}) {
    const fs::path mesh = dir / (family + ".off"), out = dir / "f.csv";
    ASSERT_EQ(run("mesh --family " + family + " --level 0 --out " + mesh.string()).status, 0);
    expect_refused(run("forces --mesh " + mesh.string() + " --method S --out " + out.string()), "valence other than 6", out);
  }
  const fs::path run_dir = dir / "run";
  expect_refused(run("shear --method S --kappa-b-hat 0.1 --mesh mt1:20 --t-end 0.1 --no-plot --out " +
                     run_dir.string()),
                 "valence other than 6", run_dir);
}

TEST_F(Cli, RefusesBadArgumentsBeforeWork) {
  const fs::path out = dir / "m.off";
  expect_refused(run("mesh --family mt1 --level -1 --out " + out.string()), "--level", out);
  expect_refused(run("mesh --family mt7 --level 2 --out " + out.string()), "--family", out);
  expect_refused(run("mesh --family mt1 --level 2 --out " + (dir / "m.stl").string()), "extension", dir / "m.stl");
  expect_refused(run("mesh --family mt1 --level 2 --radius -2 --out " + out.string()), "--radius", out);
  expect_refused(run("mesh --family mt1 --level 2 --shape oblate --axes 1,2 --out " + out.string()), "oblate", out);
  expect_refused(run("mesh --family mt1 --level 2 --out " + (dir / "nowhere" / "m.off").string()), "does not exist",
                 dir / "nowhere" / "m.off");
  const fs::path mesh = dir / "s.off";
  ASSERT_EQ(run("mesh --family mt1 --level 1 --out " + mesh.string()).status, 0);
  const fs::path csv = dir / "f.csv";
  expect_refused(run("forces --mesh " + mesh.string() + " --method Z --out " + csv.string()), "--method", csv);
  expect_refused(run("forces --mesh " + mesh.string() + " --method C --kappa-b nan --out " + csv.string()),
                 "--kappa-b", csv);
  expect_refused(run("forces --mesh " + (dir / "missing.off").string() + " --method C --out " + csv.string()),
                 "missing.off", csv);
  write(dir / "garbage.off", "OFF\n4 4 0\n0 0 zero\n");
  expect_refused(run("shape --mesh " + (dir / "garbage.off").string() + " --shape sphere --out " + csv.string()),
                 "garbage.off", csv);
}

TEST_F(Cli, IrregularFamily) {
  const fs::path out = dir / "i.off";
  const CliRun r = run("mesh --family irregular --level 2 --shape rbc --out " + out.string());
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["triangles"], 320);
  EXPECT_EQ(j["jitter"], 0.25);
  EXPECT_EQ(j["jitter_seed"], 30);  // the default base 28 + level 2
  EXPECT_TRUE(fs::exists(out));
  // The same mesh again, and another with another seed.
  const fs::path again = dir / "j.off", other = dir / "k.off";
  ASSERT_EQ(run("mesh --family irregular --level 2 --shape rbc --jitter 0.25 --jitter-seed 28 --out " + again.string()).status, 0);
  ASSERT_EQ(run("mesh --family irregular --level 2 --shape rbc --jitter-seed 5 --out " + other.string()).status, 0);
  EXPECT_EQ(slurp(out), slurp(again));
  EXPECT_NE(slurp(out), slurp(other));
}

TEST_F(Cli, RefusesAJitterThatFolds) {
  // A step of a whole mean edge length crosses the neighbours' edges.
  const fs::path out = dir / "m.off";
  expect_refused(run("mesh --family irregular --level 3 --jitter 1 --out " + out.string()),
                 "--jitter: jitter fraction 1 folds triangle", out);
  expect_refused(run("mesh --family irregular --level 3 --jitter -0.5 --out " + out.string()), "--jitter", out);
  expect_refused(run("mesh --family mt1 --level 3 --jitter 0.1 --out " + out.string()), "--family irregular only",
                 out);
  const fs::path study = dir / "study";
  expect_refused(run("rbc --families mt1,irregular --max-triangles 320 --methods C --jitter 1 --no-plots --out " +
                     study.string()),
                 "--jitter: jitter fraction 1 folds triangle", study);
  expect_refused(run("rbc --families irregular --max-triangles 320 --methods C --jitter inf --no-plots --out " +
                     study.string()),
                 "--jitter", study);
}

TEST_F(Cli, ShearRefusesBadParametersBeforeWork) {
  const fs::path out = dir / "run";
  expect_refused(run("shear --G -0.1 --out " + out.string()), "--G", out);
  expect_refused(run("shear --G inf --out " + out.string()), "--G", out);
  expect_refused(run("shear --method C --kappa-b nan --out " + out.string()), "--kappa-b", out);
  expect_refused(run("shear --method C --kappa-b-hat -1 --out " + out.string()), "--kappa-b-hat", out);
  expect_refused(run("shear --method C --kappa-b-hat 0.1 --kappa-b 1 --out " + out.string()), "excludes", out);
  expect_refused(run("shear --t-end -1 --out " + out.string()), "--t-end", out);
  expect_refused(run("shear --kappa-b 0.1 --out " + out.string()), "--method", out);
  expect_refused(run("shear --kappa-b-hat 0.1 --out " + out.string()), "--method", out);
  expect_refused(run("shear --mesh mt1:1000 --out " + out.string()), "1000", out);
  expect_refused(run("shear --mesh " + (dir / "missing.off").string() + " --out " + out.string()), "missing.off", out);
  write(dir / "open.off", off(kTetraVertices, "3 0 2 1\n3 0 1 3\n3 0 3 2\n", 4, 3));
  expect_refused(run("shear --mesh " + (dir / "open.off").string() + " --out " + out.string()), "boundary edge", out);
  expect_refused(run("shear --resume --out " + out.string()), "checkpoint", out);
}

TEST_F(Cli, ShearTakesMethodOptionsAsPartOfTheRunsIdentity) {
  const fs::path out = dir / "run";
  expect_refused(run("shear --method C --kappa-b-hat 0.1 --option degree=5 --out " + out.string()), "degree", out);
  expect_refused(run("shear --method M --kappa-b-hat 0.1 --option degree=9 --out " + out.string()), "degree", out);
  expect_refused(run("shear --method M --kappa-b-hat 0.1 --option degree --out " + out.string()), "key=value", out);
  const std::string common = "shear --method M --mesh mt1:320 --G 0.1 --kappa-b-hat 0.1 --no-plot --out " + out.string();
  CliRun r = run(common + " --option degree=4 --t-end 0.02");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto summary = nlohmann::json::parse(slurp(out / "summary.json"));
  EXPECT_EQ(summary.at("method_options").at("degree"), "4");
  // A resume with another degree is another run: refused.
  r = run(common + " --option degree=5 --t-end 0.04 --resume");
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.err.find("degree"), std::string::npos) << r.err;
  r = run(common + " --option degree=4 --t-end 0.04 --resume");
  EXPECT_EQ(r.status, 0) << r.err;
}

TEST_F(Cli, SpontaneousCurvatureAndAdeAreRefusedWhereInvalid) {
  const fs::path out = dir / "run", study = dir / "study", mesh = dir / "s.off";
  ASSERT_EQ(run("mesh --level 1 --out " + mesh.string()).status, 0);
  const std::string forces = "forces --mesh " + mesh.string() + " --out " + (dir / "f.csv").string();
  expect_refused(run(forces + " --method C --c0 nan"), "c0 must be finite", dir / "f.csv");
  expect_refused(run(forces + " --method C --c0 inf"), "c0 must be finite", dir / "f.csv");
  expect_refused(run(forces + " --method C --ade-alpha 1 --ade-d 0.1"), "--ade-area", dir / "f.csv");
  expect_refused(run(forces + " --method C --ade-alpha -1 --ade-d 0.1 --ade-area 1"), "alpha", dir / "f.csv");
  expect_refused(run(forces + " --method C --ade-alpha 1 --ade-d -0.1 --ade-area 1"), "leaflet distance",
                 dir / "f.csv");
  expect_refused(run(forces + " --method C --ade-d 0.1"), "--ade-alpha", dir / "f.csv");
  expect_refused(run(forces + " --method A --c0 1"), "method A", dir / "f.csv");
  expect_refused(run("rbc --methods A --c0 1 --max-triangles 320 --families mt1 --no-plots --out " + study.string()),
                 "method A", study);
  expect_refused(run("shear --method C --kappa-b-hat 0.1 --c0 nan --out " + out.string()), "c0", out);
  expect_refused(run("shear --c0 1 --out " + out.string()), "--method", out);
  expect_refused(run("shear --method A --kappa-b-hat 0.1 --c0 1 --out " + out.string()), "method A", out);
}

TEST_F(Cli, ShearWritesItsFilesAndResumes) {
  const fs::path out = dir / "run";
  CliRun r = run("shear --mesh mt1:320 --G 0.1 --t-end 0.3 --snapshot-every 0.1 --no-plot --out " + out.string());
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* f : {"timeseries.csv", "summary.json", "shapes.pvd", "checkpoint.json", "snapshot_00000.vtp"})
    EXPECT_TRUE(fs::exists(out / f)) << f;
  const auto summary = nlohmann::json::parse(slurp(out / "summary.json"));
  EXPECT_GT(summary["D_steady"].get<double>(), 0);
  EXPECT_NEAR(summary["final_volume"].get<double>(), summary["initial_volume"].get<double>(),
              1e-10 * summary["initial_volume"].get<double>());
  EXPECT_EQ(slurp(out / "timeseries.csv").rfind("gamma_t,D,theta,volume,area,E_bend,E_elastic,dt,axis_angle,node_phase\n",
                                                0),
            0u);
  // Continue to 0.5: the rows up to 0.3 are kept and the series ends at 0.5.
  r = run("shear --mesh mt1:320 --G 0.1 --t-end 0.5 --snapshot-every 0.1 --no-plot --resume --out " + out.string());
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string series = slurp(out / "timeseries.csv");
  const std::string last = series.substr(series.rfind('\n', series.size() - 2) + 1);
  EXPECT_NEAR(std::stod(last.substr(0, last.find(','))), 0.5, 1e-12);
  // A resume with other physics is refused.
  expect_refused(run("shear --mesh mt1:320 --G 0.2 --t-end 0.6 --resume --out " + out.string()), "G is 0.2 here",
                 out / "nothing");
}

TEST_F(Cli, ShearLbmRefusesBadLatticesBeforeWork) {
  const fs::path out = dir / "run";
  const std::string lbm = "shear --solver lbm --mesh mt1:320 ";
  expect_refused(run(lbm + "--tau 0.5 --out " + out.string()), "tau", out);
  expect_refused(run(lbm + "--box 1.5,8,10 --out " + out.string()), "does not contain the capsule", out);
  expect_refused(run(lbm + "--box 8,8,2 --out " + out.string()), "touches the walls", out);
  expect_refused(run(lbm + "--reynolds 100 --out " + out.string()), "Mach", out);
  expect_refused(run(lbm + "--radius-lu -3 --out " + out.string()), "--radius-lu", out);
  expect_refused(run(lbm + "--box 8,8 --out " + out.string()), "--box", out);
  expect_refused(run(lbm + "--kernel phi5 --out " + out.string()), "--kernel", out);
  expect_refused(run(lbm + "--rtol 1e-6 --out " + out.string()), "--rtol", out);
  expect_refused(run("shear --mesh mt1:320 --tau 1 --out " + out.string()), "--solver lbm", out);
  // Step counts beyond what a run can count (they ran without end, or wrote a row every step).
  expect_refused(run(lbm + "--t-end 1e30 --out " + out.string()), "--t-end 1e+30 (gamma t) is", out);
  expect_refused(run(lbm + "--sample-every 1e30 --out " + out.string()), "--sample-every 1e+30 (gamma t) is", out);
}

TEST_F(Cli, ShearLbmWritesTheFilesOfABimRun) {
  const fs::path bim = dir / "bim", lbm = dir / "lbm";
  CliRun r = run("shear --mesh mt1:320 --G 0.1 --t-end 0.02 --snapshot-every 0.01 --no-plot --out " + bim.string());
  ASSERT_EQ(r.status, 0) << r.err;
  // R = 4 dx in a 10 x 10 x 12 box: a few dozen lattice steps.
  r = run("shear --solver lbm --radius-lu 4 --box 2.5,2.5,3 --mesh mt1:320 --G 0.1 --t-end 0.02 "
          "--snapshot-every 0.01 --sample-every 0.005 --no-plot --out " + lbm.string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("MLUPS"), std::string::npos) << r.err;
  for (const char* f : {"timeseries.csv", "summary.json", "shapes.pvd", "checkpoint.json", "snapshot_00000.vtp"})
    EXPECT_TRUE(fs::exists(lbm / f)) << f;
  const std::string header = "gamma_t,D,theta,volume,area,E_bend,E_elastic,dt,axis_angle,node_phase\n";
  EXPECT_EQ(slurp(bim / "timeseries.csv").rfind(header, 0), 0u);
  EXPECT_EQ(slurp(lbm / "timeseries.csv").rfind(header, 0), 0u);
  const auto a = nlohmann::json::parse(slurp(bim / "summary.json"));
  const auto b = nlohmann::json::parse(slurp(lbm / "summary.json"));
  for (const auto& [key, value] : a.items())
    if (key != "rtol" && key != "atol" && key != "integrator" && key != "bim_quadrature") {  // the BIM's own
      EXPECT_TRUE(b.contains(key)) << key;
    }
  EXPECT_EQ(b["solver"], "lbm");
  EXPECT_EQ(b["lattice"]["nodes"], nlohmann::json({10, 10, 12}));
  // Rows every 0.005 in gamma t (rounded to whole lattice steps) up to t_end = 0.02.
  const auto checkpoint = nlohmann::json::parse(slurp(lbm / "checkpoint.json"));
  EXPECT_TRUE(fs::exists(lbm / checkpoint["solver_state"]["fluid"].get<std::string>()));
}

TEST_F(Cli, ComparingWithASurfaceTheNodesAreNotOnIsRefused) {
  const fs::path sphere = dir / "sphere.off";
  ASSERT_EQ(run("mesh --family mt1 --level 2 --out " + sphere.string()).status, 0);
  const fs::path out = dir / "f.csv";
  expect_refused(run("forces --mesh " + sphere.string() + " --method C --shape rbc --out " + out.string()),
                 "do not lie on the rbc surface", out);
  const fs::path shape = dir / "s.csv";
  expect_refused(run("shape --mesh " + sphere.string() + " --shape rbc --out " + shape.string()),
                 "do not lie on the rbc surface", shape);
  // The same mesh against the surface it was made for is accepted.
  EXPECT_EQ(run("forces --mesh " + sphere.string() + " --method C --shape sphere --out " + out.string()).status, 0);
}

TEST_F(Cli, ShearLbmStoppedAtAnyReportAndResumedWritesEveryFileOfTheUninterruptedRun) {
  // 4 reports, a snapshot and checkpoint after the 2nd and the 4th: a stop after the 3rd resumes
  // from the first snapshot, and its next one must come at the uninterrupted run's step.
  const std::string common = " --solver lbm --radius-lu 4 --box 2.5,2.5,3 --mesh mt1:320 --G 0.1 --t-end 0.02 "
                             "--snapshot-every 0.01 --sample-every 0.005 --no-plot --out ";
  const fs::path full = dir / "full";
  CliRun r = run("shear" + common + full.string());
  ASSERT_EQ(r.status, 0) << r.err;
  for (int k : {1, 2, 3}) {
    SCOPED_TRACE(k);
    const fs::path parts = dir / ("parts" + std::to_string(k));
    r = run("shear --stop-after-steps " + std::to_string(k) + common + parts.string());
    ASSERT_EQ(r.status, 0) << r.err;
    ASSERT_FALSE(fs::exists(parts / "summary.json"));
    r = run("shear --resume" + common + parts.string());
    ASSERT_EQ(r.status, 0) << r.err;
    expect_same_run_files(full, parts);
  }
}

TEST_F(Cli, ShearStoppedAndResumedEqualsUninterrupted) {
  const std::string common = " --mesh mt1:320 --G 0.1 --t-end 0.3 --snapshot-every 0.1 --no-plot --out ";
  const fs::path full = dir / "full", parts = dir / "parts";
  CliRun r = run("shear" + common + full.string());
  ASSERT_EQ(r.status, 0) << r.err;
  r = run("shear --stop-after-steps 4" + common + parts.string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("stopped after 4 steps"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(parts / "summary.json"));
  r = run("shear --resume" + common + parts.string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(slurp(parts / "timeseries.csv"), slurp(full / "timeseries.csv"));
  auto a = nlohmann::json::parse(slurp(full / "summary.json"));
  auto b = nlohmann::json::parse(slurp(parts / "summary.json"));
  EXPECT_EQ(a, b);
}

TEST_F(Cli, ShearMaxStepsFailsARunThatExceedsItsBudgetAndKeepsTheCheckpoint) {
  // The budget counts the accepted steps of all parts: a run that needs N steps passes with the
  // budget N and fails with N - 1; a resume of a run that spent its budget fails at its first step.
  const std::string common = " --mesh mt1:320 --G 0.1 --t-end 0.3 --snapshot-every 0.02 --no-plot --out ";
  const fs::path full = dir / "full", capped = dir / "capped";
  CliRun r = run("shear" + common + full.string());
  ASSERT_EQ(r.status, 0) << r.err;
  const auto steps = nlohmann::json::parse(slurp(full / "summary.json")).at("steps").get<std::int64_t>();
  ASSERT_GT(steps, 3);
  r = run("shear --max-steps " + std::to_string(steps) + common + (dir / "exact").string());
  ASSERT_EQ(r.status, 0) << r.err;
  r = run("shear --max-steps " + std::to_string(steps - 1) + common + capped.string());
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.err.find("more than " + std::to_string(steps - 1) + " accepted steps (the budget of --max-steps)"),
            std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(capped / "summary.json"));
  ASSERT_TRUE(fs::exists(capped / "checkpoint.json"));
  r = run("shear --resume --max-steps " + std::to_string(steps - 1) + common + capped.string());
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.err.find("--max-steps"), std::string::npos) << r.err;
  r = run("shear --resume" + common + capped.string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(slurp(capped / "timeseries.csv"), slurp(full / "timeseries.csv"));
  expect_refused(run("shear --solver lbm --max-steps 10 --out " + (dir / "lbm").string()), "--max-steps", dir / "lbm");
}

TEST_F(Cli, ShearRkcStoppedAndResumedEqualsUninterrupted) {
  // The stiff case (Method C, kappa_b_hat = 0.15) with the Runge-Kutta-Chebyshev integrator: its
  // controller memory and spectral radius travel in the checkpoint, so the resumed run repeats the
  // uninterrupted one byte for byte.
  const std::string common = " --integrator rkc --method C --mesh mt1:320 --G 0.2 --kappa-b-hat 0.15 --t-end 0.4"
                             " --snapshot-every 0.1 --no-plot --out ";
  const fs::path full = dir / "full", parts = dir / "parts";
  CliRun r = run("shear" + common + full.string());
  ASSERT_EQ(r.status, 0) << r.err;
  r = run("shear --stop-after-steps 5" + common + parts.string());
  ASSERT_EQ(r.status, 0) << r.err;
  r = run("shear --resume" + common + parts.string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(slurp(parts / "timeseries.csv"), slurp(full / "timeseries.csv"));
  auto a = nlohmann::json::parse(slurp(full / "summary.json"));
  auto b = nlohmann::json::parse(slurp(parts / "summary.json"));
  EXPECT_EQ(a, b);
  EXPECT_EQ(a["integrator"], "rkc");
  EXPECT_GT(a["integrator_stats"]["spectral_radius"].get<double>(), 0.0);
  // Resuming with the other integrator is refused: the integrator is part of the run's identity.
  expect_refused(run("shear --integrator cash-karp --resume --method C --mesh mt1:320 --G 0.2 --kappa-b-hat 0.15"
                     " --t-end 0.5 --no-plot --out " + parts.string()),
                 "integrator", parts / "nothing");
  expect_refused(run("shear --integrator euler --mesh mt1:320 --no-plot --out " + (dir / "e").string()), "integrator",
                 dir / "e");
}

TEST_F(Cli, ShearBimQuadratureIsRecordedAndPartOfTheIdentity) {
  const fs::path out = dir / "adaptive";
  const std::string common = " --mesh mt1:320 --G 0.1 --t-end 0.02 --snapshot-every 0.01 --no-plot --out ";
  CliRun r = run("shear --bim-quadrature adaptive --stop-after-steps 1" + common + out.string());
  ASSERT_EQ(r.status, 0) << r.err;
  r = run("shear --bim-quadrature adaptive --resume" + common + out.string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(slurp(out / "summary.json"))["bim_quadrature"], "adaptive");
  // The reference is the default; resuming an adaptive run with it is refused.
  expect_refused(run("shear --resume" + common + out.string()), "bim_quadrature", out / "nothing");
  const fs::path ref = dir / "all7";
  ASSERT_EQ(run("shear" + common + ref.string()).status, 0);
  EXPECT_EQ(nlohmann::json::parse(slurp(ref / "summary.json"))["bim_quadrature"], "all7");
  const fs::path tree = dir / "tree";
  ASSERT_EQ(run("shear --bim-quadrature tree" + common + tree.string()).status, 0);
  EXPECT_EQ(nlohmann::json::parse(slurp(tree / "summary.json"))["bim_quadrature"], "tree");
  const fs::path mixed = dir / "tree-mixed";
  ASSERT_EQ(run("shear --bim-quadrature tree-mixed" + common + mixed.string()).status, 0);
  EXPECT_EQ(nlohmann::json::parse(slurp(mixed / "summary.json"))["bim_quadrature"], "tree-mixed");
  expect_refused(run("shear --bim-quadrature fast" + common + (dir / "f").string()), "bim-quadrature", dir / "f");
  expect_refused(run("shear --solver lbm --bim-quadrature adaptive" + common + (dir / "l").string()),
                 "--bim-quadrature", dir / "l");
}

TEST_F(Cli, ShearModuliAndMissingPlotScript) {
  // --kappa-b is dimensional: kB = kappa_b_hat / G with R = mu = gamma = 1.
  const fs::path out = dir / "run";
  CliRun r = run("shear --method C --mesh mt1:320 --G 0.1 --kappa-b 0.375 --t-end 0.005 --plot-script " +
                 (dir / "missing.py").string() + " --out " + out.string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("warning: the plot was not made"), std::string::npos) << r.err;
  const auto summary = nlohmann::json::parse(slurp(out / "summary.json"));
  EXPECT_NEAR(summary["kappa_b_hat"].get<double>(), 0.0375, 1e-15);
  EXPECT_NEAR(summary["kappa_b"].get<double>(), 0.375, 1e-14);
  const auto checkpoint = nlohmann::json::parse(slurp(out / "checkpoint.json"));
  EXPECT_EQ(checkpoint["arguments"]["kappa_b_hat"], summary["kappa_b_hat"]);
  EXPECT_EQ(checkpoint["version"], 2);
  // The same run given kappa_b_hat resumes it (the same physics).
  r = run("shear --method C --mesh mt1:320 --G 0.1 --kappa-b-hat 0.0375 --t-end 0.006 --no-plot --resume --out " +
          out.string());
  EXPECT_EQ(r.status, 0) << r.err;
}

namespace {
/// Every path below `root`, relative to it.
std::set<std::string> tree(const fs::path& root) {
  std::set<std::string> out;
  for (const auto& entry : fs::recursive_directory_iterator(root))
    out.insert(fs::relative(entry.path(), root).string());
  return out;
}
}  // namespace

TEST_F(Cli, FileNamesWithQuotesSpacesAndSemicolonsAreTakenLiterally) {
  // Names a shell would split or act on: the files land exactly there and nothing else appears.
  const fs::path base = dir / "a b;c 'd' \"e\" $(f) `g`";
  fs::create_directories(base);
  const std::string mesh = "m e;sh 'x' \"y\".off", forces = "f; rm -rf x 'q' \"r\".csv",
                    rbc = "rbc out; echo \"z\" 'w'", shear = "run; touch x 'a' \"b\"";
  CliRun r = run({"mesh", "--family", "mt1", "--level", "1", "--out", (base / mesh).string()});
  ASSERT_EQ(r.status, 0) << r.err;
  r = run({"forces", "--mesh", (base / mesh).string(), "--method", "C", "--out", (base / forces).string()});
  ASSERT_EQ(r.status, 0) << r.err;
  r = run({"rbc", "--families", "mt1", "--max-triangles", "320", "--methods", "C", "--no-plots", "--out",
           (base / rbc).string()});
  ASSERT_EQ(r.status, 0) << r.err;
  r = run({"shear", "--mesh", "mt1:320", "--t-end", "0.01", "--snapshot-every", "0.01", "--no-plot", "--out",
           (base / shear).string()});
  ASSERT_EQ(r.status, 0) << r.err;
  const std::set<std::string> all = tree(base);
  std::set<std::string> top;
  for (const auto& e : fs::directory_iterator(base)) top.insert(e.path().filename().string());
  EXPECT_EQ(top, (std::set<std::string>{mesh, forces, rbc, shear}));
  EXPECT_TRUE(fs::is_regular_file(base / mesh));
  EXPECT_TRUE(fs::is_regular_file(base / forces));
  EXPECT_TRUE(fs::is_regular_file(base / rbc / "errors.csv"));
  for (const char* f : {"timeseries.csv", "summary.json", "shapes.pvd", "checkpoint.json", "snapshot_00000.vtp"})
    EXPECT_TRUE(fs::is_regular_file(base / shear / f)) << f;
  for (const std::string& p : all) EXPECT_EQ(p.find(".tmp"), std::string::npos) << p;
  // Nothing appeared beside the folder either (the test's own stdout.txt and stderr.txt aside).
  std::set<std::string> beside;
  for (const auto& e : fs::directory_iterator(dir)) beside.insert(e.path().filename().string());
  EXPECT_EQ(beside, (std::set<std::string>{base.filename().string(), "stdout.txt", "stderr.txt"}));
}

TEST_F(Cli, ForcesRefusesANonFiniteResultNamingTheVertex) {
  // A huge bending modulus on a small sphere (H^3 = 1e9) overflows F: the result is refused,
  // naming the method, the quantity and the vertex, and no file is written.
  const fs::path mesh = dir / "s.off", out = dir / "f.csv";
  ASSERT_EQ(run("mesh --family mt1 --level 1 --radius 1e-3 --out " + mesh.string()).status, 0);
  const CliRun r = run("forces --mesh " + mesh.string() + " --method C --kappa-b 1e305 --out " + out.string());
  expect_refused(r, "method C: ", out);
  EXPECT_NE(r.err.find("is not finite at vertex"), std::string::npos) << r.err;
}

TEST_F(Cli, ShearRefusesLooseTolerancesAndWarnsAboutLooseOnes) {
  const fs::path out = dir / "run";
  expect_refused(run("shear --rtol 0.1 --atol 0.1 --out " + out.string()), "--rtol", out);
  expect_refused(run("shear --atol 0.05 --out " + out.string()), "--atol", out);
  expect_refused(run("shear --rtol 0 --out " + out.string()), "--rtol", out);
  const CliRun r = run("shear --mesh mt1:320 --rtol 1e-3 --t-end 0.005 --no-plot --out " + out.string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("warning: --rtol 0.001 is above 0.0001"), std::string::npos) << r.err;
}

TEST_F(Cli, ShearResumeToAnEarlierEndIsRefusedAndToItsOwnEndCompletesTheRun) {
  const fs::path out = dir / "run";
  const std::string common = "shear --mesh mt1:320 --snapshot-every 0.01 --no-plot --out " + out.string();
  ASSERT_EQ(run(common + " --t-end 0.02").status, 0);
  const std::string summary = slurp(out / "summary.json"), series = slurp(out / "timeseries.csv");
  for (const char* t_end : {"0.0199", "0.01"}) {
    const CliRun r = run(common + " --resume --t-end " + t_end);
    EXPECT_NE(r.status, 0);
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_NE(r.err.find("is before the checkpoint's gamma t"), std::string::npos) << r.err;
    EXPECT_EQ(slurp(out / "summary.json"), summary);
    EXPECT_EQ(slurp(out / "timeseries.csv"), series);
  }
  // Stopped between the final checkpoint and summary.json: a resume to the same end writes it.
  fs::remove(out / "summary.json");
  const CliRun r = run(common + " --resume --t-end 0.02");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(slurp(out / "summary.json"), summary);
  EXPECT_EQ(slurp(out / "timeseries.csv"), series);
}

TEST_F(Cli, ShearSkalakLawIsRecordedAndPartOfTheRunsIdentity) {
  const std::string common = " --mesh mt1:320 --G 0.1 --t-end 0.2 --snapshot-every 0.1 --integrator rkc --no-plot --out ";
  const fs::path out = dir / "skalak", full = dir / "skalak_full";
  CliRun r = run("shear --membrane skalak --skalak-c 2 --stop-after-steps 5" + common + out.string());
  ASSERT_EQ(r.status, 0) << r.err;
  // Resuming under the neo-Hookean law, or with another C, is refused naming the law.
  expect_refused(run("shear --resume" + common + out.string()), "membrane law skalak with C = 2", dir / "nothing");
  expect_refused(run("shear --resume --membrane skalak --skalak-c 3" + common + out.string()), "C = 2",
                 dir / "nothing");
  r = run("shear --resume --membrane skalak --skalak-c 2" + common + out.string());
  ASSERT_EQ(r.status, 0) << r.err;
  r = run("shear --membrane skalak --skalak-c 2" + common + full.string());
  ASSERT_EQ(r.status, 0) << r.err;
  auto a = nlohmann::json::parse(slurp(out / "summary.json"));
  auto b = nlohmann::json::parse(slurp(full / "summary.json"));
  EXPECT_EQ(a["membrane_law"], "skalak");
  EXPECT_EQ(a["skalak_c"].get<double>(), 2.0);
  EXPECT_EQ(a, b);
  // A neo-Hookean run names its law and cannot be resumed as a Skalak one.
  const fs::path nh = dir / "nh";
  r = run("shear --stop-after-steps 3" + common + nh.string());
  ASSERT_EQ(r.status, 0) << r.err;
  expect_refused(run("shear --resume --membrane skalak" + common + nh.string()), "membrane law neo-hookean",
                 dir / "nothing");
  r = run("shear --resume" + common + nh.string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(slurp(nh / "summary.json"))["membrane_law"], "neo-hookean");
  // Inadmissible or misplaced C, unknown law: refused before any file is written.
  expect_refused(run("shear --membrane skalak --skalak-c -0.5" + common + (dir / "bad").string()), "--skalak-c",
                 dir / "bad");
  expect_refused(run("shear --membrane neo-hookean --skalak-c 2" + common + (dir / "bad").string()), "--skalak-c",
                 dir / "bad");
  expect_refused(run("shear --membrane mooney" + common + (dir / "bad").string()), "--membrane", dir / "bad");
}

// Issue 29: nothing lost, nothing trusted blindly.

TEST_F(Cli, EmptyNumbersAndRingsOutOfRangeAreRefused) {
  const fs::path mesh = dir / "s.off", out = dir / "o.csv", run_dir = dir / "run";
  ASSERT_EQ(run("mesh --family mt1 --level 1 --out " + mesh.string()).status, 0);
  expect_refused(run({"mesh", "--level", "", "--out", (dir / "m.off").string()}), "'' is not a number",
                 dir / "m.off");
  expect_refused(run({"shear", "--method", "C", "--kappa-b-hat", "", "--out", run_dir.string()}),
                 "'' is not a number", run_dir);
  expect_refused(run({"shear", "--membrane", "skalak", "--skalak-c", "", "--out", run_dir.string()}),
                 "'' is not a number", run_dir);
  expect_refused(run({"forces", "--mesh", mesh.string(), "--method", "C", "--kappa-b", "", "--out", out.string()}),
                 "'' is not a number", out);
  expect_refused(run({"shape", "--mesh", mesh.string(), "--shape", "sphere", "--kappa-b", "", "--out", out.string()}),
                 "'' is not a number", out);
  const fs::path rbc = dir / "rbc";
  expect_refused(run({"rbc", "--rings", "0", "--no-plots", "--out", rbc.string()}), "--rings", rbc);
  expect_refused(run({"rbc", "--rings", "", "--no-plots", "--out", rbc.string()}), "--rings", rbc);
}

TEST_F(Cli, ShearRefusesAFolderWhoseParentIsMissing) {
  const fs::path out = dir / "a" / "b" / "c";
  expect_refused(run("shear --mesh mt1:320 --t-end 0.01 --no-plot --out " + out.string()), "does not exist", out);
  EXPECT_FALSE(fs::exists(dir / "a"));
}

TEST_F(Cli, ShearRefusesASecondRunIntoALockedFolder) {
  // The first run's lock, held by this process: the second run is refused at once, deterministically.
  const fs::path out = dir / "run";
  fs::create_directories(out);
  const int fd = ::open((out / ".lock").c_str(), O_RDWR | O_CREAT, 0644);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(::flock(fd, LOCK_EX | LOCK_NB), 0);
  const CliRun r = run("shear --mesh mt1:320 --G 0.2 --t-end 0.01 --no-plot --out " + out.string());
  ::close(fd);
  expect_refused(r, "in use by another run", out / "timeseries.csv");
}

TEST_F(Cli, ShearNeedsOverwriteToReplaceAnotherRun) {
  const fs::path out = dir / "run";
  const std::string args = "shear --mesh mt1:320 --t-end 0.02 --snapshot-every 0.005 --no-plot --out " + out.string();
  ASSERT_EQ(run(args + " --G 0.1").status, 0);
  const std::string series = slurp(out / "timeseries.csv");
  const CliRun refused = run(args + " --G 0.2");
  EXPECT_EQ(refused.status, 1);
  EXPECT_NE(refused.err.find("--overwrite"), std::string::npos) << refused.err;
  EXPECT_EQ(slurp(out / "timeseries.csv"), series);
  // --overwrite replaces it, and leaves none of the old run's snapshots beside the new.
  const CliRun r = run("shear --mesh mt1:320 --t-end 0.01 --snapshot-every 0.005 --no-plot --G 0.2 --overwrite --out " +
                       out.string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(slurp(out / "timeseries.csv"), series);
  EXPECT_TRUE(fs::exists(out / "snapshot_00002.vtp"));
  EXPECT_FALSE(fs::exists(out / "snapshot_00003.vtp"));
  expect_refused(run("shear --mesh mt1:320 --t-end 0.03 --snapshot-every 0.005 --no-plot --G 0.2 --resume --overwrite "
                     "--out " + out.string()),
                 "excludes", out / "nothing");
}

TEST_F(Cli, ShearResumeRefusesACheckpointThatIsNotARegularFile) {
  const fs::path out = dir / "run";
  fs::create_directories(out);
  ASSERT_EQ(::mkfifo((out / "checkpoint.json").c_str(), 0644), 0);
  // A FIFO is refused at once (reading it would wait for a writer forever).
  CliRun r = run("shear --mesh mt1:320 --t-end 0.01 --no-plot --resume --out " + out.string());
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("FIFO"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("checkpoint.json"), std::string::npos) << r.err;
  fs::remove(out / "checkpoint.json");
  fs::create_directory(out / "checkpoint.json");
  r = run("shear --mesh mt1:320 --t-end 0.01 --no-plot --resume --out " + out.string());
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("a folder"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("checkpoint.json"), std::string::npos) << r.err;
}

TEST_F(Cli, AWriteBeyondTheFileSizeLimitIsAnErrorAndLeavesNoTemporary) {
  // ulimit -f: the write fails (EFBIG) instead of SIGXFSZ killing bendlab mid-write.
  struct rlimit old {};
  ASSERT_EQ(::getrlimit(RLIMIT_FSIZE, &old), 0);
  struct rlimit small = old;
  small.rlim_cur = 64 * 1024;
  ASSERT_EQ(::setrlimit(RLIMIT_FSIZE, &small), 0);
  const fs::path out = dir / "m.vtp";
  const CliRun r = run("mesh --family mt1 --level 5 --out " + out.string());
  ASSERT_EQ(::setrlimit(RLIMIT_FSIZE, &old), 0);
  expect_refused(r, "error while writing", out);
  EXPECT_NE(r.err.find("m.vtp"), std::string::npos) << r.err;
}

TEST_F(Cli, TwoDisjointSurfacesAreRefused) {
  // Two tetrahedra: each closed and outward, together not one surface.
  const std::string second = "5 5 5\n6 5 5\n5 6 5\n5 5 6\n";
  const std::string faces2 = "3 4 6 5\n3 4 5 7\n3 4 7 6\n3 5 6 7\n";
  write(dir / "two.off", off(kTetraVertices + second, kTetraFaces + faces2, 8, 8));
  const fs::path out = dir / "f.csv";
  expect_refused(run("forces --mesh " + (dir / "two.off").string() + " --method C --out " + out.string()),
                 "several components", out);
  expect_refused(run("shear --mesh " + (dir / "two.off").string() + " --out " + (dir / "run").string()),
                 "several components", dir / "run");
}

TEST_F(Cli, ShearShapeOptionsAreCheckedAndPartOfTheRunsIdentity) {
  const fs::path out = dir / "run";
  expect_refused(run("shear --shape rbc --aspect 0.5 --out " + out.string()), "--aspect", out);
  expect_refused(run("shear --shape oblate --aspect 1.5 --out " + out.string()), "--aspect", out);
  expect_refused(run("shear --shape prolate --aspect 0.5 --out " + out.string()), "--aspect", out);
  expect_refused(run("shear --shape rbc --tilt 200 --out " + out.string()), "--tilt", out);
  expect_refused(run("shear --shape rbc --reference-aspect 0.5 --out " + out.string()), "--reference-aspect", out);
  expect_refused(run("shear --shape rbc --reference-shape oblate --reference-aspect 2 --out " + out.string()),
                 "--reference-aspect", out);
  const std::string common = "shear --shape rbc --tilt 30 --mesh mt1:320 --G 0.1 --no-plot --out " + out.string();
  CliRun r = run(common + " --t-end 0.01");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto summary = nlohmann::json::parse(slurp(out / "summary.json"));
  EXPECT_EQ(summary.at("shape"), "rbc");
  EXPECT_EQ(summary.at("tilt").get<double>(), 30.0);
  EXPECT_EQ(summary.at("capsule_shape").at("shape"), "rbc");
  EXPECT_TRUE(summary.contains("motion"));
  // Another tilt, or another reference, is another run: refused on resume.
  r = run("shear --shape rbc --tilt 40 --mesh mt1:320 --G 0.1 --no-plot --t-end 0.02 --resume --out " + out.string());
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.err.find("tilt"), std::string::npos) << r.err;
  r = run(common + " --reference-shape sphere --t-end 0.02 --resume");
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.err.find("reference_shape"), std::string::npos) << r.err;
  r = run(common + " --t-end 0.02 --resume");
  EXPECT_EQ(r.status, 0) << r.err;
  // The lattice Boltzmann solver takes the shape too: it starts from the cell and keeps its volume.
  const fs::path lbm = dir / "lbm";
  r = run("shear --solver lbm --radius-lu 4 --box 4,4,4 --shape rbc --tilt 30 --reference-shape oblate --mesh mt1:320 "
          "--G 0.1 --t-end 0.01 --snapshot-every 0.01 --sample-every 0.005 --no-plot --out " + lbm.string());
  ASSERT_EQ(r.status, 0) << r.err;
  const auto l = nlohmann::json::parse(slurp(lbm / "summary.json"));
  EXPECT_EQ(l.at("reference_shape"), "oblate");
  EXPECT_NEAR(l.at("initial_volume").get<double>(), l.at("capsule_shape").at("mesh_volume").get<double>(), 1e-12);
}

// What a hostile-input probe found: shapes, numbers and messages.

TEST_F(Cli, ShearRefusesAZeroAspectAndABoxShorterThanTheShape) {
  const fs::path out = dir / "run";
  expect_refused(run("shear --shape oblate --aspect 0 --mesh mt1:320 --out " + out.string()), "--aspect 0", out);
  expect_refused(run("shear --shape rbc --reference-shape oblate --reference-aspect 0 --mesh mt1:320 --out " +
                     out.string()),
                 "--reference-aspect 0", out);
  // A prolate spheroid of c/a = 4 lying along x is 15 nodes long at R = 3: a 9-node period would
  // hold it overlapping its own image.
  expect_refused(run("shear --solver lbm --shape prolate --aspect 4 --tilt 90 --mesh mt1:320 --radius-lu 3 "
                     "--box 3,3,4 --out " + out.string()),
                 "box x of 9 nodes does not contain the capsule", out);
}

TEST_F(Cli, SeedsAreWholeNumbersWithinTheirRange) {
  const fs::path out = dir / "m.off", study = dir / "study";
  // CLI11 took each of these for 2^64 - 1. (Every unsigned option has the same check: rbc's once.)
  for (const char* seed : {"-1", "18446744073709551616", "1e23", "1.5"})
    expect_refused(run({"mesh", "--family", "irregular", "--level", "1", "--jitter-seed", seed, "--out", out.string()}),
                   "--jitter-seed", out);
  expect_refused(run({"rbc", "--families", "irregular", "--max-triangles", "320", "--methods", "C", "--jitter-seed",
                      "-1", "--no-plots", "--out", study.string()}),
                 "--jitter-seed", study);
  const CliRun r = run("mesh --family irregular --level 1 --jitter-seed 18446744073709551614 --out " + out.string());
  ASSERT_EQ(r.status, 0) << r.err;
  // Level 1 uses the base seed + 1: the largest seed there is.
  EXPECT_EQ(nlohmann::json::parse(r.out).at("jitter_seed").get<std::uint64_t>(), 18446744073709551615ull);
}

TEST_F(Cli, ShearNamesAnOverflowingAdeTermBeforeWork) {
  const fs::path out = dir / "run";
  expect_refused(run("shear --method C --mesh mt1:320 --kappa-b-hat 0.05 --ade-alpha 1 --ade-d 1e-300 --ade-da0 0.1 "
                     "--t-end 0.05 --no-plot --out " + out.string()),
                 "ADE term", out);
}

TEST_F(Cli, RbcRefusesAnOverflowingForceLawBeforeWork) {
  // The exact force density of c0 = 1e308 overflows: refused before the study starts, naming the
  // option, and without the output folder.
  const fs::path study = dir / "study";
  expect_refused(run("rbc --families mt1 --max-triangles 320 --methods C --c0 1e308 --no-plots --out " +
                     study.string()),
                 "--c0", study);
}

TEST_F(Cli, RbcWithAPythonThatCannotStartWarnsAndSucceeds) {
  // The data files are the results; a plot not made is a warning, whatever the reason.
  const fs::path study = dir / "study";
  const CliRun r = run({"rbc", "--families", "mt1", "--max-triangles", "320", "--methods", "C", "--python",
                        "/nonexistent/python3", "--out", study.string()});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("warning: the plots were not made"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("/nonexistent/python3"), std::string::npos) << r.err;
  EXPECT_TRUE(fs::is_regular_file(study / "errors.csv"));
}
