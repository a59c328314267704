// Method S (paper section 2.5, METHOD_S.md): patches on meshes, energy, gradient, forces, options.
#include <gtest/gtest.h>

#include <Eigen/SparseLU>

#include <cmath>
#include <numbers>
#include <random>

#include "bendlab/bending/loop_shell.hpp"
#include "bendlab/bending/loop_shell_energy.hpp"
#include "bendlab/bending/loop_shell_limit.hpp"
#include "bendlab/bending/loop_shell_mass.hpp"
#include "bendlab/bending/loop_shell_patches.hpp"
#include "bendlab/geometry/mesh_geometry.hpp"
#include "bendlab/mesh/generators.hpp"
#include "bendlab/surfaces/analytic_surface.hpp"

namespace bendlab {
namespace {

using namespace loop_shell;

Points perturbed(const Points& x, double amplitude, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-amplitude, amplitude);
  Points y = x;
  for (Eigen::Index i = 0; i < y.size(); ++i) y.data()[i] += u(rng);
  return y;
}

// The point of face f's chart (f's barycentrics (v, w)) as barycentrics of patch g's chart, and
// the Jacobian d(v_g, w_g)/d(v_f, w_f), for the two patches of an edge. Charts are unfolded so
// that the quad of f and g is a parallelogram (the regular lattice of the box splines).
struct ChartMap {
  Eigen::Vector2d origin;  // g's (v, w) at f's (0, 0)
  Eigen::Matrix2d jac;
};
ChartMap chart_map(const Topology& t, const LoopPatches& p, int f, int g) {
  // f-chart positions of f's corners by face-corner index.
  Eigen::Vector2d pos_f[3];
  const Eigen::Vector2d base[3] = {{0, 0}, {1, 0}, {0, 1}};
  for (int c = 0; c < 3; ++c) pos_f[(p.corner[f] + c) % 3] = base[c];
  std::map<int, Eigen::Vector2d> at;
  for (int c = 0; c < 3; ++c) at[t.faces()(f, c)] = pos_f[c];
  int opposite_f = -1, opposite_g = -1;
  for (int c = 0; c < 3; ++c) {
    bool shared = false;
    for (int d = 0; d < 3; ++d) shared |= t.faces()(f, c) == t.faces()(g, d);
    if (!shared) opposite_f = t.faces()(f, c);
  }
  for (int d = 0; d < 3; ++d)
    if (!at.count(t.faces()(g, d))) opposite_g = t.faces()(g, d);
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  for (const auto& [v, q] : at)
    if (v != opposite_f) sum += q;
  at[opposite_g] = sum - at[opposite_f];
  // g's corners u, v, w in the f chart.
  Eigen::Vector2d gc[3];
  for (int c = 0; c < 3; ++c) gc[c] = at[t.faces()(g, (p.corner[g] + c) % 3)];
  Eigen::Matrix2d e;
  e.col(0) = gc[1] - gc[0];
  e.col(1) = gc[2] - gc[0];
  ChartMap m;
  m.jac = e.inverse();
  m.origin = m.jac * (-gc[0]);
  return m;
}

TEST(LoopShell, PatchesAreContinuousAcrossSharedEdges) {
  // Value and first derivatives of neighbouring patches agree along every shared edge (C1), and
  // the second derivatives too where both patches are regular (C2).
  const TriMesh m = sphere_mesh(MeshFamily::MT1, 2);
  const Topology& t = m.topology();
  const LoopPatches p = LoopPatches::build(t);
  const Points x = perturbed(m.positions(), 0.05, 11);
  double worst0 = 0, worst1 = 0, worst2 = 0;
  for (int e = 0; e < t.num_edges(); ++e) {
    const int f = t.edge_faces()(e, 0), g = t.edge_faces()(e, 1);
    const ChartMap map = chart_map(t, p, f, g);
    // The edge in f's chart: the two shared corners.
    std::vector<Eigen::Vector2d> ends;
    const Eigen::Vector2d base[3] = {{0, 0}, {1, 0}, {0, 1}};
    for (int c = 0; c < 3; ++c) {
      const int vtx = t.faces()(f, (p.corner[f] + c) % 3);
      if (vtx == t.edge_vertices()(e, 0) || vtx == t.edge_vertices()(e, 1)) ends.push_back(base[c]);
    }
    for (double s : {0.1, 0.37, 0.5, 0.81}) {
      const Eigen::Vector2d yf = (1 - s) * ends[0] + s * ends[1];
      const Eigen::Vector2d yg = map.origin + map.jac * yf;
      const PatchBasis bf = patch_basis(p.valence[f], yf.x(), yf.y());
      const PatchBasis bg = patch_basis(p.valence[g], std::max(0.0, yg.x()), std::max(0.0, yg.y()));
      Eigen::Matrix<double, 6, 3> df = Eigen::Matrix<double, 6, 3>::Zero(), dg = df;
      for (Eigen::Index i = 0; i < bf.cols(); ++i) df += bf.col(i) * x.row(p.face_points(f)[i]);
      for (Eigen::Index i = 0; i < bg.cols(); ++i) dg += bg.col(i) * x.row(p.face_points(g)[i]);
      worst0 = std::max(worst0, (df.row(0) - dg.row(0)).norm());
      // d/dy_f = (d/dy_g) jac.
      Eigen::Matrix<double, 3, 2> gf, gg;
      gf << df.row(1).transpose(), df.row(2).transpose();
      gg << dg.row(1).transpose(), dg.row(2).transpose();
      worst1 = std::max(worst1, (gf - gg * map.jac).norm());
      if (p.valence[f] == 6 && p.valence[g] == 6) {
        for (int k = 0; k < 3; ++k) {
          Eigen::Matrix2d hf, hg;
          hf << df(3, k), df(4, k), df(4, k), df(5, k);
          hg << dg(3, k), dg(4, k), dg(4, k), dg(5, k);
          worst2 = std::max(worst2, (hf - map.jac.transpose() * hg * map.jac).norm());
        }
      }
    }
  }
  EXPECT_LT(worst0, 1e-12);
  EXPECT_LT(worst1, 1e-12);
  EXPECT_LT(worst2, 1e-11);
}

TEST(LoopShell, LimitMasksEqualPatchEvaluationAtTheCorners) {
  const TriMesh m = sphere_mesh(MeshFamily::MT1, 1);
  const Topology& t = m.topology();
  const LoopPatches p = LoopPatches::build(t);
  const Points x = perturbed(m.positions(), 0.05, 2);
  const Points limit = limit_matrix(t) * x;
  const Points normals = limit_normals(t, x);
  const Eigen::Vector2d corners[3] = {{0, 0}, {1, 0}, {0, 1}};
  for (int f = 0; f < t.num_faces(); ++f)
    for (int c = 0; c < 3; ++c) {
      const int vtx = t.faces()(f, (p.corner[f] + c) % 3);
      // An extraordinary corner (c = 0, valence != 6) only in the limit v, w -> 0.
      const bool ev = c == 0 && p.valence[f] != 6;
      const double v = ev ? 1e-10 : corners[c].x(), w = ev ? 1e-10 : corners[c].y();
      const SurfacePoint s = surface_point(patch_basis(p.valence[f], v, w), x, p.face_points(f));
      EXPECT_LT((s.x - row(limit, vtx)).norm(), ev ? 1e-8 : 1e-13) << f << " " << c;
      EXPECT_LT((s.n - row(normals, vtx)).norm(), ev ? 1e-4 : 1e-12) << f << " " << c;
    }
}

TEST(LoopShell, SymmetricLimitSolveEqualsTheLuSolveOfL) {
  // LimitSolver (LDL^T of the symmetric S, L = diag(chi) S) against a plain LU of L, on meshes
  // with extraordinary vertices of valence 4 and 5.
  for (const TriMesh& m : {sphere_mesh(MeshFamily::MT1, 2), sphere_mesh(MeshFamily::Octa, 2)}) {
    const Topology& t = m.topology();
    const Points x = perturbed(make_rbc(1.0)->map_from_unit_sphere(m.positions()), 0.01, 3);
    Eigen::SparseLU<Eigen::SparseMatrix<double>> lu(limit_matrix(t));
    const Eigen::MatrixXd ref = lu.solve(Eigen::MatrixXd(x));
    const Points p = LimitSolver(t).solve(x);
    EXPECT_LE((p - ref).cwiseAbs().maxCoeff(), 1e-12 * ref.cwiseAbs().maxCoeff());
    EXPECT_LE((limit_matrix(t) * p - x).cwiseAbs().maxCoeff(), 1e-13);
  }
}

TEST(LoopShell, SphereEnergyTendsToEightPiKappa) {
  const TriMesh m = sphere_mesh(MeshFamily::MT1, 4);  // 5120 triangles
  const auto s = LoopShellMethod::create({});
  const double kappa_b = 1.7;
  const double e = *s->energy(m.topology(), m.positions(), kappa_b);
  EXPECT_LT(std::abs(e / (8 * std::numbers::pi * kappa_b) - 1.0), 1e-4);
}

TEST(LoopShell, GradientMatchesCentralDifferences) {
  const TriMesh m = sphere_mesh(MeshFamily::MT1, 2);  // 320 triangles
  const Points x = perturbed(make_rbc()->map_from_unit_sphere(m.positions()), 0.01, 7);
  const LoopShellMethod s(LoopShellMethod::Control::Nodes, 6, LoopShellMethod::HMode::Limit);
  Points grad;
  s.control_energy(m.topology(), x, 1.0, &grad);
  const double h = 1e-6, scale = grad.cwiseAbs().maxCoeff();
  for (int i : {0, 5, 17, 100, 161}) {
    for (int k = 0; k < 3; ++k) {
      Points xp = x, xm = x;
      xp(i, k) += h, xm(i, k) -= h;
      const double fd = (s.control_energy(m.topology(), xp, 1.0) - s.control_energy(m.topology(), xm, 1.0)) / (2 * h);
      EXPECT_NEAR(grad(i, k), fd, 1e-6 * scale) << i << " " << k;
    }
  }
}

TEST(LoopShell, EnergyIsInvariantUnderRigidMotionsAndForcesBalance) {
  const TriMesh m = sphere_mesh(MeshFamily::MT1, 2);
  const Points x = perturbed(make_rbc()->map_from_unit_sphere(m.positions()), 0.02, 9);
  const LoopShellMethod s(LoopShellMethod::Control::Solve, 6, LoopShellMethod::HMode::Limit);
  const Mat3 rot = Eigen::AngleAxisd(0.7, Vec3(1, 2, -0.5).normalized()).toRotationMatrix();
  Points y = (x * rot.transpose()).rowwise() + Eigen::RowVector3d(0.3, -2.0, 1.1);
  const double e0 = *s.energy(m.topology(), x, 1.0), e1 = *s.energy(m.topology(), y, 1.0);
  EXPECT_NEAR(e1, e0, 1e-12 * e0);
  const LoopShellState st = s.state(m.topology(), x, 1.0);
  EXPECT_NEAR(st.energy, e0, 1e-12 * e0);
  const double scale = st.control_force.cwiseAbs().maxCoeff();
  Vec3 sum = Vec3::Zero(), torque = Vec3::Zero();
  double virial = 0;
  for (int i = 0; i < m.num_vertices(); ++i) {
    sum += row(st.control_force, i);
    torque += row(st.control, i).cross(row(st.control_force, i));
    virial += row(st.control, i).dot(row(st.control_force, i));  // E_B is scale invariant
  }
  EXPECT_LT(sum.norm(), 1e-11 * scale);
  EXPECT_LT(torque.norm(), 1e-11 * scale);
  EXPECT_LT(std::abs(virial), 1e-11 * scale);
  // The node positions are the limit points of the control points.
  EXPECT_LT((limit_matrix(m.topology()) * st.control - x).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(LoopShell, MassMatrixIntegratesToTheArea) {
  const TriMesh m = sphere_mesh(MeshFamily::MT1, 2);
  const LoopPatches p = LoopPatches::build(m.topology());
  const QuadratureBases bases(dunavant_rule(6), {5, 6});
  const MassPattern pattern(p, m.num_vertices());
  Eigen::SparseMatrix<double> mm = pattern.pattern();
  pattern.assemble(p, bases, m.positions(), mm);
  const Eigen::VectorXd one = Eigen::VectorXd::Ones(m.num_vertices());
  EXPECT_NEAR(one.dot(mm * one), shell_area(p, bases, m.positions()), 1e-12);
  EXPECT_LT((Eigen::SparseMatrix<double>(mm.transpose()) - mm).norm(), 1e-15);
  EXPECT_LE(mm.nonZeros(), 37L * m.num_vertices());
}

TEST(LoopShell, SphereResultIsNearlyExact) {
  // Unit sphere, 1280 triangles: f vanishes, H = K = 1, n = x (the nodes are limit points).
  const TriMesh m = sphere_mesh(MeshFamily::MT1, 3);
  for (const char* h : {"limit", "projection"}) {
    const auto s = LoopShellMethod::create({{"H", h}});
    const BendingResult r = s->compute(m.topology(), m.positions(), 1.0);
    double en = 0, eh = 0;
    for (int i = 0; i < m.num_vertices(); ++i) {
      en = std::max(en, (r.normal.row(i) - m.positions().row(i)).norm());
      eh += std::abs(r.H[i] - 1.0) / m.num_vertices();
    }
    EXPECT_LT(en, 1e-2) << h;
    EXPECT_LT(eh, 1e-2) << h;
    EXPECT_TRUE(std::isnan(r.lapH[0]));
    for (int i = 0; i < m.num_vertices(); ++i)
      EXPECT_LT((r.force.row(i) - r.force_density.row(i) * r.area[i]).norm(), 1e-14);
  }
}

TEST(LoopShell, ForceDensityHasTheConventionalSignOnTheRbc) {
  // docs/conventions.md: f = 2 kB (lapH + 2 H (H^2 - K)) n. A sign error would give eps_f near 2.
  const TriMesh m = sphere_mesh(MeshFamily::MT1, 3);
  const auto rbc = make_rbc();
  const Points x = rbc->map_from_unit_sphere(m.positions());
  const SurfaceFields exact = rbc->evaluate(x);
  const BendingResult r = LoopShellMethod::create({})->compute(m.topology(), x, 1.0);
  double ef = 0;
  for (int i = 0; i < m.num_vertices(); ++i) ef += (exact.f.row(i) - r.force_density.row(i)).norm();
  EXPECT_LT(ef / m.num_vertices() / rbc->maxima().f, 0.1);
}

TEST(LoopShell, ConjugateGradientsAgreeWithTheFactorisation) {
  const TriMesh m = sphere_mesh(MeshFamily::MT1, 2);
  const Points x = make_rbc()->map_from_unit_sphere(m.positions());
  const BendingResult cg = LoopShellMethod::create({{"H", "projection"}})->compute(m.topology(), x, 1.0);
  const BendingResult ldlt =
      LoopShellMethod::create({{"H", "projection"}, {"solver", "ldlt"}})->compute(m.topology(), x, 1.0);
  const double scale = ldlt.force_density.cwiseAbs().maxCoeff();
  EXPECT_LT((cg.force_density - ldlt.force_density).cwiseAbs().maxCoeff(), 1e-8 * scale);
  EXPECT_LT((cg.H - ldlt.H).cwiseAbs().maxCoeff(), 1e-8);
}

TEST(LoopShell, ForcesEqualTheReferencePipeline) {
  // The whole force with the exact solver (solver=ldlt) against the same steps done by the
  // plain reference pieces: LU of L, the serial shell_energy and MassPattern::assemble, a sparse
  // LDL^T of M, Meyer's area from MeshGeometry::compute. Valences 4, 5 and 6.
  for (const TriMesh& m : {sphere_mesh(MeshFamily::MT1, 2), sphere_mesh(MeshFamily::Octa, 2)}) {
    const Topology& t = m.topology();
    const Points x = perturbed(make_rbc(1.0)->map_from_unit_sphere(m.positions()), 0.005, 5);
    Points force;
    LoopShellMethod::create({{"solver", "ldlt"}})->forces(t, x, 1.3, force);

    const Eigen::SparseMatrix<double> l = limit_matrix(t);
    Eigen::SparseLU<Eigen::SparseMatrix<double>> lu(l);
    const Eigen::MatrixXd pc = lu.solve(Eigen::MatrixXd(x));
    const Points control = pc;
    const LoopPatches patches = LoopPatches::build(t);
    const QuadratureBases bases(dunavant_rule(6), {4, 5, 6});
    Points gradient;
    shell_energy(patches, bases, control, 1.3, &gradient);
    const MassPattern mass(patches, t.num_vertices());
    Eigen::SparseMatrix<double> mm = mass.pattern();
    mass.assemble(patches, bases, control, mm);
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(mm);
    const Eigen::MatrixXd fc = ldlt.solve(-Eigen::MatrixXd(gradient));
    const Eigen::MatrixXd density = l * fc;
    const Points ref = density.array().colwise() * MeshGeometry::compute(t, x).mixed_area.array();
    EXPECT_LE((force - ref).cwiseAbs().maxCoeff(), 1e-12 * ref.cwiseAbs().maxCoeff());
  }
}

TEST(LoopShell, IcosahedronIsRefusedNamingAFace) {
  const TriMesh m = icosahedron();
  try {
    LoopShellMethod::create({})->compute(m.topology(), m.positions(), 1.0);
    FAIL() << "no error";
  } catch (const Error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("face 0"), std::string::npos) << what;
    EXPECT_NE(what.find("refine"), std::string::npos) << what;
  }
}

TEST(LoopShell, OptionsAreChecked) {
  EXPECT_THROW(LoopShellMethod::create({{"rings", "2"}}), Error);
  EXPECT_THROW(LoopShellMethod::create({{"gauss", "5"}}), Error);
  EXPECT_THROW(LoopShellMethod::create({{"control", "limit"}}), Error);
  EXPECT_THROW(LoopShellMethod::create({{"H", "fit"}}), Error);
  EXPECT_THROW(LoopShellMethod::create({{"solver", "gmres"}}), Error);
  EXPECT_EQ(make_bending_method("S", {{"gauss", "12"}, {"control", "nodes"}, {"H", "projection"}})->name(), "S");
}

}  // namespace
}  // namespace bendlab
