#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "bendlab/analysis/rbc_study.hpp"
#include "bendlab/mesh/generators.hpp"
#include "bendlab/surfaces/analytic_surface.hpp"

using namespace bendlab;

TEST(RbcStudy, PolarAngle) {
  Points x(4, 3);
  x << 0, 0, 2, 0, 0, -1, 3, 0, 0, 1, 0, 1;
  const Scalars t = polar_angle(x);
  EXPECT_DOUBLE_EQ(t[0], 0);
  EXPECT_DOUBLE_EQ(t[1], std::numbers::pi);
  EXPECT_DOUBLE_EQ(t[2], std::numbers::pi / 2);
  EXPECT_NEAR(t[3], std::numbers::pi / 4, 1e-15);
}

TEST(RbcStudy, RefusesBadOptions) {
  RbcStudyOptions o;
  o.families = {"mt3"};
  EXPECT_THROW(validate(o), Error);
  o = {};
  o.max_triangles = 319;
  EXPECT_THROW(validate(o), Error);
  o = {};
  o.methods = {"Z"};
  EXPECT_THROW(validate(o), Error);
  o = {};
  o.methods = {"C", "C"};
  EXPECT_THROW(validate(o), Error);
  o = {};
  o.families = {};
  EXPECT_THROW(validate(o), Error);
  o = {};
  o.method_options = {{"rings", "7"}};  // reaches the fitting methods E and ED, which refuse it
  EXPECT_THROW(validate(o), Error);
  o.method_options = {{"rings", "2"}};
  EXPECT_NO_THROW(validate(o));  // and only them: A-D take no options
}

TEST(RbcStudy, TinyStudyGivesEveryRowWithFiniteErrors) {
  RbcStudyOptions o;
  o.families = {"mt1"};
  o.max_triangles = 1280;
  int lines = 0;
  o.progress = [&](const std::string&) { ++lines; };
  const RbcStudyResult r = run_rbc_study(o);

  // Denominators of eq. (17) for R = 1, kB = 1 (docs/conventions.md §3).
  EXPECT_NEAR(r.maxima.H, 2.20098, 1e-4);
  EXPECT_NEAR(r.maxima.f, 189.457, 1e-2);

  ASSERT_EQ(r.meshes.size(), 2u);
  EXPECT_EQ(r.meshes[0].triangles, 320);
  EXPECT_EQ(r.meshes[1].triangles, 1280);
  EXPECT_GT(r.meshes[0].h, r.meshes[1].h);
  EXPECT_EQ(lines, 2 * (1 + static_cast<int>(o.methods.size())));

  std::size_t expected_rows = 0;
  for (const MeshRun& m : r.meshes) {
    ASSERT_EQ(m.methods.size(), o.methods.size());
    EXPECT_TRUE(m.has_nodes);
    EXPECT_EQ(m.theta.size(), m.vertices);
    EXPECT_GE(m.theta.minCoeff(), 0.0);
    EXPECT_LE(m.theta.maxCoeff(), std::numbers::pi);
    for (const MethodRun& run : m.methods) {
      EXPECT_GE(run.seconds, 0.0);
      // Every method gives a force density; the variational ones also H and Lap H.
      EXPECT_TRUE(run.errors[static_cast<int>(Quantity::F)].available) << run.method;
      const MethodCapabilities& c = bending_method_info(run.method).capabilities;
      EXPECT_EQ(run.errors[static_cast<int>(Quantity::LapH)].available, c.defines_lapH) << run.method;
      if (c.defines_H && c.defines_lapH) {
        EXPECT_TRUE(run.errors[static_cast<int>(Quantity::H)].available) << run.method;
        EXPECT_TRUE(run.errors[static_cast<int>(Quantity::LapH)].available) << run.method;
      }
      for (const ErrorSummary& s : run.errors) expected_rows += s.available;
    }
  }
  const auto rows = r.rows();
  EXPECT_EQ(rows.size(), expected_rows);
  for (const ErrorRow& row : rows) {
    EXPECT_TRUE(std::isfinite(row.max_error)) << row.method << " " << row.quantity;
    EXPECT_TRUE(std::isfinite(row.avg_error)) << row.method << " " << row.quantity;
    EXPECT_GE(row.max_error, row.avg_error) << row.method << " " << row.quantity;
    EXPECT_GT(row.avg_error, 0.0) << row.method << " " << row.quantity;
  }
  // Two resolutions are enough for a slope in every series.
  for (const RateFit& f : fit_rates(rows, {"mt1"})) EXPECT_NE(f.fit.trend, Trend::Undetermined);
}

TEST(RbcStudy, InhomogeneousMeshesComeFromTheirFamilies) {
  RbcStudyOptions o;
  o.families = {"inhomogeneous"};
  o.methods = {"C"};
  o.max_triangles = 320;  // does not limit the inhomogeneous meshes
  const RbcStudyResult r = run_rbc_study(o);
  ASSERT_EQ(r.meshes.size(), 2u);
  EXPECT_EQ(r.meshes[0].family, "rivara-mt1");
  EXPECT_EQ(r.meshes[0].origin, "mt1");
  EXPECT_EQ(r.meshes[1].family, "rivara-mt2");
  for (const MeshRun& m : r.meshes) {
    EXPECT_TRUE(m.inhomogeneous);
    // Three passes that bisect every triangle at least once: more than 320 * 2^3 triangles.
    EXPECT_GT(m.triangles, 2560);
    EXPECT_EQ(m.triangles % 2, 0);  // a closed triangle mesh has an even face count
  }
}

TEST(RbcStudy, MethodSRefusesTheRivaraMeshesWithoutEndingTheStudy) {
  RbcStudyOptions o;
  o.families = {"mt1", "inhomogeneous"};
  o.methods = {"C", "S"};
  o.max_triangles = 320;
  const RbcStudyResult r = run_rbc_study(o);
  ASSERT_EQ(r.meshes.size(), 3u);
  // MT1 meshes are admissible for S: errors available.
  EXPECT_TRUE(r.meshes[0].methods[1].refused.empty());
  EXPECT_TRUE(r.meshes[0].methods[1].errors[static_cast<std::size_t>(Quantity::F)].available);
  for (std::size_t k = 1; k < 3; ++k) {
    const MeshRun& m = r.meshes[k];
    EXPECT_TRUE(m.methods[0].refused.empty()) << m.family;  // C runs
    const MethodRun& s = m.methods[1];
    EXPECT_NE(s.refused.find("method S: face"), std::string::npos) << s.refused;
    EXPECT_FALSE(s.has_nodes);
    for (const ErrorSummary& e : s.errors) EXPECT_FALSE(e.available);
  }
  // No rows for the refused runs; table 3 shows n/a for S.
  for (const ErrorRow& row : r.rows()) EXPECT_FALSE(row.method == "S" && row.family != "mt1") << row.family;
  const std::string md = table3_markdown({}, {"C", "S"}, {"S"});
  EXPECT_NE(md.find("| n/a |"), std::string::npos) << md;
}

TEST(RbcStudy, PolarBaseRotatesTheIcosahedron) {
  RbcStudyOptions o;
  o.families = {"mt1"};
  o.methods = {"C"};
  o.max_triangles = 320;
  o.base = "polar";
  const RbcStudyResult r = run_rbc_study(o);
  ASSERT_EQ(r.meshes.size(), 1u);
  // Vertices 0 and 3 (the icosahedron's, kept by refinement) sit at the poles in the polar base,
  // not in the default one.
  EXPECT_NEAR(r.meshes[0].theta[0], 0.0, 1e-12);
  EXPECT_NEAR(r.meshes[0].theta[3], std::numbers::pi, 1e-12);
  o.base = "default";
  const RbcStudyResult d = run_rbc_study(o);
  EXPECT_GT(d.meshes[0].theta[0], 0.1);
  o.base = "sideways";
  EXPECT_THROW(validate(o), Error);
}

TEST(RbcStudy, IrregularFamilyIsMT1JitteredAfreshOnEveryLevel) {
  RbcStudyOptions o;
  o.families = {"irregular"};
  o.methods = {"C"};
  o.max_triangles = 1280;
  const RbcStudyResult r = run_rbc_study(o);
  ASSERT_EQ(r.meshes.size(), 2u);
  const auto rbc = make_rbc(1.0);
  for (int k = 0; k < 2; ++k) {
    const MeshRun& m = r.meshes[k];
    EXPECT_EQ(m.family, "irregular");
    EXPECT_EQ(m.origin, "irregular");
    EXPECT_FALSE(m.inhomogeneous);
    EXPECT_EQ(m.level, k + 2);
    EXPECT_EQ(m.triangles, 320 << (2 * k));
    EXPECT_EQ(m.x, rbc->map_from_unit_sphere(irregular_sphere_mesh(m.level).positions()));
  }
  o.jitter_seed = 1;
  o.max_triangles = 320;
  const RbcStudyResult other = run_rbc_study(o);
  EXPECT_EQ(other.meshes[0].x, rbc->map_from_unit_sphere(irregular_sphere_mesh(2, 0.25, 1).positions()));
  EXPECT_NE(other.meshes[0].x, r.meshes[0].x);
}

TEST(RbcStudy, IrregularFamilyLeavesTheOtherFamiliesAlone) {
  RbcStudyOptions o;
  o.families = {"mt1"};
  o.methods = {"C"};
  o.max_triangles = 320;
  const std::vector<ErrorRow> alone = run_rbc_study(o).rows();
  o.families = {"irregular", "mt1"};
  std::vector<ErrorRow> both = run_rbc_study(o).rows();
  both.erase(std::remove_if(both.begin(), both.end(), [](const ErrorRow& e) { return e.family == "irregular"; }),
             both.end());
  ASSERT_EQ(both.size(), alone.size());
  for (std::size_t i = 0; i < both.size(); ++i) {
    EXPECT_EQ(both[i].family, alone[i].family);
    EXPECT_EQ(both[i].quantity, alone[i].quantity);
    EXPECT_EQ(both[i].max_error, alone[i].max_error);  // bit for bit
    EXPECT_EQ(both[i].avg_error, alone[i].avg_error);
  }
}

TEST(RbcStudy, RefusesAJitterThatFoldsBeforeAnyWork) {
  RbcStudyOptions o;
  o.families = {"mt1", "irregular"};
  o.methods = {"C"};
  o.max_triangles = 320;
  o.jitter = 1.0;  // a whole mean edge length: the neighbours' edges are crossed
  int lines = 0;
  o.progress = [&](const std::string&) { ++lines; };
  try {
    run_rbc_study(o);
    FAIL() << "a jitter of 1 was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("--jitter: jitter fraction 1 folds triangle"), std::string::npos) << e.what();
  }
  EXPECT_EQ(lines, 0);  // not even the MT1 mesh ran
  o.jitter = -0.1;
  EXPECT_THROW(validate(o), Error);
  o.jitter = NAN;
  EXPECT_THROW(validate(o), Error);
  o.jitter = 1.0;
  o.families = {"mt1"};
  EXPECT_NO_THROW(validate(o));  // no irregular mesh in the study
}
