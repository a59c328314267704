// Optical-tweezers stretching (flow/optical_stretch.hpp) on the 162-vertex red blood cell: the
// pulled sets, the measures, the stress-free start, the force balance and the residual of every
// equilibrium, and the monotone response. Exact invariants only: no number of a run is pasted here.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <string>
#include <vector>

#include "bendlab/flow/optical_stretch.hpp"
#include "bendlab/geometry/measures.hpp"

using namespace bendlab;

namespace {
StretchSpec coarse_cell() {
  StretchSpec s;
  s.cell.mesh = "mt1:320";
  s.forces_pN = {0};
  return s;
}
}  // namespace

TEST(OpticalStretch, PulledVertexCountIsTheRoundedFraction) {
  EXPECT_EQ(pulled_vertex_count(0.02, 642), 13);  // 12.84
  EXPECT_EQ(pulled_vertex_count(0.02, 162), 3);   // 3.24
  EXPECT_EQ(pulled_vertex_count(0.5, 162), 81);   // the two halves
  EXPECT_THROW(pulled_vertex_count(0.003, 162), Error);  // 0.49 rounds to none
  EXPECT_THROW(pulled_vertex_count(0.5, 161), Error);    // 81 + 81 > 161
}

TEST(OpticalStretch, RefusesBadSpecsNamingTheOption) {
  auto message = [](StretchSpec s) {
    try {
      check_stretch(s);
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  StretchSpec s = coarse_cell();
  s.forces_pN = {0, -1};
  EXPECT_NE(message(s).find("--forces"), std::string::npos);
  s.forces_pN = {NAN};
  EXPECT_NE(message(s).find("--forces"), std::string::npos);
  s.forces_pN = {};
  EXPECT_NE(message(s).find("--forces"), std::string::npos);
  s = coarse_cell();
  s.fraction = 0.6;
  EXPECT_NE(message(s).find("--fraction"), std::string::npos);
  s.fraction = 0;
  EXPECT_NE(message(s).find("--fraction"), std::string::npos);
  s = coarse_cell();
  s.tolerance_pN = 0;
  EXPECT_NE(message(s).find("--tolerance"), std::string::npos);
  s = coarse_cell();
  s.cell.shear_modulus = INFINITY;
  EXPECT_NE(message(s).find("--shear-modulus"), std::string::npos);
  s = coarse_cell();
  s.cell.bending_modulus = -1e-19;
  EXPECT_NE(message(s).find("--bending-modulus"), std::string::npos);
  EXPECT_EQ(message(coarse_cell()), "");
}

TEST(OpticalStretch, TransverseDiameterIsTheLargestWidthAcrossX) {
  // A tetrahedron whose shadow on the y-z plane is the unit square: its extents in y and z are 1,
  // its largest width across x the square's diagonal, sqrt(2).
  const auto t = Topology::build(4, (Faces(4, 3) << 0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3).finished());
  Points x(4, 3);
  x << 0, 0, 0, 0, 1, 0, 0, 0, 1, 5, 1, 1;
  const StretchMeasures m = stretch_measures(*t, x);
  EXPECT_EQ(m.axial_um, 5.0);
  EXPECT_EQ(m.extent_y_um, 1.0);
  EXPECT_EQ(m.extent_z_um, 1.0);
  EXPECT_DOUBLE_EQ(m.transverse_um, std::sqrt(2.0));
}

TEST(OpticalStretch, PullsTheEndsAlongXWithNoNetForce) {
  OpticalStretch run(coarse_cell());
  const Points& ref = run.cell().reference_um.positions();
  const std::vector<int>& right = run.right_vertices();
  const std::vector<int>& left = run.left_vertices();
  ASSERT_EQ(right.size(), 3u);
  ASSERT_EQ(left.size(), 3u);
  std::set<int> r(right.begin(), right.end()), l(left.begin(), left.end());
  double right_min = INFINITY, left_max = -INFINITY;
  for (int i : right) right_min = std::min(right_min, ref(i, 0));
  for (int i : left) left_max = std::max(left_max, ref(i, 0));
  for (int i = 0; i < ref.rows(); ++i) {
    EXPECT_FALSE(r.count(i) && l.count(i));
    if (!r.count(i)) {
      EXPECT_LE(ref(i, 0), right_min) << i;
    }
    if (!l.count(i)) {
      EXPECT_GE(ref(i, 0), left_max) << i;
    }
  }
  const Points a = run.applied_forces(30);
  EXPECT_EQ(a.col(0).sum(), 0.0);
  EXPECT_EQ(a.col(1).cwiseAbs().sum(), 0.0);
  EXPECT_EQ(a.col(2).cwiseAbs().sum(), 0.0);
  double pull = 0;
  for (int i : right) pull += a(i, 0);
  EXPECT_NEAR(pull, 30.0, 1e-12);
}

TEST(OpticalStretch, StressFreeCellWithoutBendingIsItsOwnEquilibrium) {
  // kappa_B = 0: the reference shape has no elastic force and its own volume, so at F = 0 the
  // relaxation takes no step and the diameters are the shape's, 2 R = 7.82 um (the mesh has
  // vertices on the rim at x = +-R and y = +-R).
  StretchSpec s = coarse_cell();
  s.cell.bending_modulus = 0;
  OpticalStretch run(s);
  const StretchPoint p = run.equilibrate(0);
  EXPECT_TRUE(p.converged);
  EXPECT_EQ(p.iterations, 0);
  EXPECT_LT(p.residual_pN, s.tolerance_pN);
  EXPECT_NEAR(p.measures.axial_um, 2 * 3.91, 1e-12);
  EXPECT_NEAR(p.measures.transverse_um, 2 * 3.91, 1e-12);
  EXPECT_EQ(p.area_change, 0.0);
  EXPECT_EQ(p.volume_change, 0.0);
}

TEST(OpticalStretch, EveryEquilibriumBalancesItsForcesAndStretchesMonotonically) {
  StretchSpec s = coarse_cell();
  OpticalStretch run(s);
  const int n = run.membrane().num_vertices();
  std::vector<StretchPoint> points;
  for (double f : {0.0, 20.0, 40.0, 80.0}) {
    const StretchPoint p = run.equilibrate(f);
    ASSERT_TRUE(p.converged) << f << " pN: " << p.failure;
    EXPECT_LT(p.residual_pN, s.tolerance_pN);
    // The residual is what the run reports: recompute it from the final shape.
    Points fm;
    run.membrane().forces(run.positions(), fm);
    EXPECT_EQ((fm - run.membrane_force()).cwiseAbs().maxCoeff(), 0.0);
    const Points r = fm + run.applied_forces(f);
    EXPECT_DOUBLE_EQ(r.rowwise().norm().maxCoeff(), p.residual_pN);
    // The applied forces cancel exactly; then the membrane's sum is the residuals' sum.
    EXPECT_EQ(p.applied_force_sum_pN, 0.0);
    EXPECT_LE(p.membrane_force_sum_pN, n * s.tolerance_pN);
    points.push_back(p);
  }
  // At F = 0 the biconcave shape only yields to its own bending force (it is no bending
  // equilibrium): its diameters stay within a percent of 7.82 um.
  EXPECT_NEAR(points[0].measures.axial_um, 7.82, 0.01 * 7.82);
  EXPECT_NEAR(points[0].measures.transverse_um, 7.82, 0.01 * 7.82);
  for (std::size_t k = 1; k < points.size(); ++k) {
    EXPECT_GT(points[k].measures.axial_um, points[k - 1].measures.axial_um) << k;
    EXPECT_LT(points[k].measures.transverse_um, points[k - 1].measures.transverse_um) << k;
  }
}

TEST(OpticalStretch, NeoHookeanCellStretchesToo) {
  StretchSpec s = coarse_cell();
  s.cell.elastic_law = "neo-hookean";
  OpticalStretch run(s);
  const StretchPoint p0 = run.equilibrate(0);
  const StretchPoint p1 = run.equilibrate(40);
  ASSERT_TRUE(p0.converged && p1.converged) << p0.failure << p1.failure;
  EXPECT_GT(p1.measures.axial_um, p0.measures.axial_um);
}

TEST(OpticalStretch, EveryMethodHoldsTheUnloadedCellStillAndMostStretchIt) {
  // mt1:1280, the study's mesh: every method relaxes the reference cell at F = 0 (Method M did not
  // before its Laplacian and relaxation changed: docs/results/rbc_stretch.md), with the relaxation
  // --relaxation auto picks, and all but three stretch it to 100 pN in one go. Open (issue: every
  // bending method where cells move): ED does not settle under load with either relaxation, and M
  // diverges beyond about 20 pN; M is held to the unloaded cell and a small load here.
#if defined(__SANITIZE_ADDRESS__)
  const std::vector<std::string> methods = {"M"};  // the sanitizers make the rest too slow
#else
  const std::vector<std::string> methods = {"A", "B", "C", "D", "E", "ED", "S", "J", "M"};
#endif
  for (const std::string& method : methods) {
    StretchSpec s;
    s.cell.mesh = "mt1:1280";
    s.cell.method = method;
    s.forces_pN = {0};
    OpticalStretch run(s);
    EXPECT_EQ(run.spec().relaxation, default_relaxation(method)) << method;
    const StretchPoint p0 = run.equilibrate(0);
    ASSERT_TRUE(p0.converged) << method << ": " << p0.failure;
    // The unloaded cell stays within 5 % of its reference diameters (7.82 um): it yields only to its
    // own bending force, which is no equilibrium of the biconcave shape (A's dihedral-angle energy,
    // whose modulus is not the Helfrich one on this mesh, moves it most, by about 4 %), and no
    // growing mode runs away with it.
    EXPECT_NEAR(p0.measures.axial_um, 7.82, 0.05 * 7.82) << method;
    EXPECT_NEAR(p0.measures.transverse_um, 7.82, 0.05 * 7.82) << method;
    // S costs 20 s to stretch on this mesh (the study does it); ED does not settle under load.
    if (method == "ED" || method == "S") continue;
    const double load = method == "M" ? 15.987 : 100.0;  // Mills et al.'s first force for M
    const StretchPoint p1 = run.equilibrate(load);
    ASSERT_TRUE(p1.converged) << method << " at " << load << " pN: " << p1.failure;
    EXPECT_GT(p1.measures.axial_um, p0.measures.axial_um + 1.0) << method;
    EXPECT_LT(p1.measures.transverse_um, p0.measures.transverse_um) << method;
  }
}
