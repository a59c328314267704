// Method S: the fused, coloured, OpenMP assembly (loop_shell_assembly.hpp) against the serial
// reference (shell_energy + MassPattern::assemble), thread-count independence, and the warm-started
// mass solve.
#include <gtest/gtest.h>
#include <omp.h>

#include <random>
#include <set>

#include "bendlab/bending/loop_shell.hpp"
#include "bendlab/bending/loop_shell_assembly.hpp"
#include "bendlab/bending/loop_shell_solve.hpp"
#include "bendlab/mesh/generators.hpp"
#include "bendlab/surfaces/analytic_surface.hpp"

namespace bendlab {
namespace {

using namespace loop_shell;

struct ShellSetup {
  TriMesh mesh;
  LoopPatches patches;
  QuadratureBases bases;
  MassPattern mass;
  FaceColouring colouring;
  Points control;
  explicit ShellSetup(const TriMesh& m)
      : mesh(m),
        patches(LoopPatches::build(m.topology())),
        bases(dunavant_rule(6), {4, 5, 6}),
        mass(patches, m.num_vertices()),
        colouring(FaceColouring::build(patches, m.num_vertices())) {
    // An irregular shape: the RBC with a small deterministic perturbation.
    control = make_rbc(1.0)->map_from_unit_sphere(m.positions());
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(-0.01, 0.01);
    for (Eigen::Index i = 0; i < control.size(); ++i) control.data()[i] += u(rng);
  }
};

TEST(LoopShellAssembly, ColoursSeparatePatchesAndCoverEveryFace) {
  const ShellSetup s(sphere_mesh(MeshFamily::Octa, 2));
  // Blocks of faces (default) and single faces.
  for (const FaceColouring& colouring :
       {s.colouring, FaceColouring::build(s.patches, s.mesh.num_vertices(), 1)}) {
    std::vector<int> seen(s.patches.num_faces(), 0);
    ASSERT_EQ(colouring.blocks.back(), s.patches.num_faces());
    for (int c = 0; c < colouring.num_colours(); ++c) {
      // Blocks of one colour share no control point; they cover the colour's faces.
      std::set<int> points;
      EXPECT_EQ(colouring.blocks[colouring.block_offsets[c]], colouring.offsets[c]);
      for (int j = colouring.block_offsets[c]; j < colouring.block_offsets[c + 1]; ++j) {
        std::set<int> block;
        for (int k = colouring.blocks[j]; k < colouring.blocks[j + 1]; ++k) {
          const int f = colouring.faces[k];
          ++seen[f];
          for (int a = 0; a < s.patches.valence[f] + 6; ++a) block.insert(s.patches.face_points(f)[a]);
        }
        for (const int p : block) EXPECT_TRUE(points.insert(p).second) << "colour " << c << " block " << j;
      }
    }
    for (int f = 0; f < s.patches.num_faces(); ++f) EXPECT_EQ(seen[f], 1) << f;
  }
}

TEST(LoopShellAssembly, FusedAssemblyEqualsTheSerialReference) {
  for (const TriMesh& mesh : {sphere_mesh(MeshFamily::MT1, 2), sphere_mesh(MeshFamily::Octa, 2)}) {
    const ShellSetup s(mesh);
    Points g_ref;
    const double e_ref = shell_energy(s.patches, s.bases, s.control, 1.3, &g_ref);
    Eigen::SparseMatrix<double> m_ref = s.mass.pattern();
    Eigen::VectorXd h_ref;
    s.mass.assemble(s.patches, s.bases, s.control, m_ref, &h_ref);

    Points g;
    Eigen::SparseMatrix<double> m = s.mass.pattern();
    Eigen::VectorXd h;
    // The serial pass (this size) and the coloured one on the threads (parallel_faces = 0).
    for (const int parallel_faces : {kParallelFaces, 0}) {
      const double e =
          shell_energy_mass(s.patches, s.bases, s.mass, s.colouring, s.control, 1.3, g, m, &h, parallel_faces);
      EXPECT_NEAR(e, e_ref, 1e-13 * e_ref);
      EXPECT_LE((g - g_ref).cwiseAbs().maxCoeff(), 1e-12 * g_ref.cwiseAbs().maxCoeff());
      EXPECT_LE(Eigen::MatrixXd(m - m_ref).cwiseAbs().maxCoeff(),
                1e-14 * Eigen::MatrixXd(m_ref).cwiseAbs().maxCoeff());
      EXPECT_LE((h - h_ref).cwiseAbs().maxCoeff(), 1e-14 * h_ref.cwiseAbs().maxCoeff());
    }
  }
}

TEST(LoopShellAssembly, FixedSizeFaceKernelEqualsTheReferenceForEveryValence) {
  // face_energy_fast (tabulated products, fixed sizes) against face_energy on one patch of each
  // valence it serves, with random control points near a flat patch (positive area element).
  std::vector<int> valences;
  for (int n = 3; n <= FaceWork::kMaxFastValence; ++n) valences.push_back(n);
  const QuadratureBases bases(dunavant_rule(6), valences);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-0.05, 0.05);
  for (const int n : valences) {
    const int m = n + 6;
    Points p(m, 3);
    // Any non-degenerate positions serve the comparison: a wavy spiral, perturbed.
    for (int a = 0; a < m; ++a) p.row(a) << std::cos(0.7 * a) * (1 + 0.1 * a), std::sin(0.7 * a) * (1 + 0.1 * a),
                                            0.2 * std::cos(1.3 * a) + u(rng);
    std::vector<int> idx(m);
    for (int a = 0; a < m; ++a) idx[a] = a;
    FaceLocal local;
    local.with_mass = local.with_h = true;
    const double e_ref = face_energy(bases.at(n), bases.rule(), p, idx.data(), 1.7, &local);
    FaceWork work;
    double e = 0.0;
    ASSERT_TRUE(face_energy_fast(bases, n, p, idx.data(), 1.7, true, work, e));
    ASSERT_EQ(work.m, m);
    EXPECT_NEAR(e, e_ref, 1e-13 * std::abs(e_ref)) << n;
    const double gmax = local.gradient.cwiseAbs().maxCoeff(), mmax = local.mass.cwiseAbs().maxCoeff();
    const double hmax = local.h.cwiseAbs().maxCoeff();
    int k = 0;
    for (int a = 0; a < m; ++a) {
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(work.gradient[a][c], local.gradient(a, c), 1e-12 * gmax) << n;
      for (int b = a; b < m; ++b) EXPECT_NEAR(work.mass[k++], local.mass(a, b), 1e-14 * mmax) << n;
      EXPECT_NEAR(work.h[a], local.h[a], 1e-13 * hmax) << n;
    }
  }
  // Valences beyond the fixed-size kernels are left to the reference.
  const QuadratureBases wide(dunavant_rule(6), {FaceWork::kMaxFastValence + 1});
  FaceWork work;
  double e = 0.0;
  const Points p = Points::Zero(FaceWork::kMaxFastValence + 7, 3);
  std::vector<int> idx(FaceWork::kMaxFastValence + 7, 0);
  EXPECT_FALSE(face_energy_fast(wide, FaceWork::kMaxFastValence + 1, p, idx.data(), 1.0, false, work, e));
}

TEST(LoopShellAssembly, GradientAndMassDoNotDependOnTheThreadCount) {
  const ShellSetup s(sphere_mesh(MeshFamily::MT1, 2));
  const int before = omp_get_max_threads();
  Points g1, g2;
  Eigen::SparseMatrix<double> m1 = s.mass.pattern(), m2 = s.mass.pattern();
  omp_set_num_threads(1);
  // parallel_faces = 0: the threads take part whatever the size.
  const double e1 = shell_energy_mass(s.patches, s.bases, s.mass, s.colouring, s.control, 1.0, g1, m1, nullptr, 0);
  omp_set_num_threads(2);
  const double e2 = shell_energy_mass(s.patches, s.bases, s.mass, s.colouring, s.control, 1.0, g2, m2, nullptr, 0);
  omp_set_num_threads(before);
  EXPECT_NEAR(e1, e2, 1e-13 * e1);
  EXPECT_EQ(g1, g2);
  EXPECT_EQ(Eigen::MatrixXd(m1), Eigen::MatrixXd(m2));
}

TEST(LoopShellAssembly, ForcesOnOneAndTwoThreadsAgree) {
  // 5120 triangles: above kParallelFaces, so the coloured assembly runs on the threads (and the
  // rest of the pipeline). One method object with the exact solver, so that its per-topology
  // set-up is paid once; the CG solve's thread independence is the next test.
  const TriMesh mesh = sphere_mesh(MeshFamily::MT1, 4);
  ASSERT_GE(mesh.num_faces(), kParallelFaces);
  const Points x = make_rbc(1.0)->map_from_unit_sphere(mesh.positions());
  const auto exact = LoopShellMethod::create({{"solver", "ldlt"}});
  const int before = omp_get_max_threads();
  Points f1, f2;
  omp_set_num_threads(1);
  exact->forces(mesh.topology(), x, 1.0, f1);
  omp_set_num_threads(2);
  exact->forces(mesh.topology(), x, 1.0, f2);
  omp_set_num_threads(before);
  EXPECT_LE((f1 - f2).cwiseAbs().maxCoeff(), 1e-13 * f1.cwiseAbs().maxCoeff());
}

TEST(LoopShellAssembly, MassSolveOnOneAndTwoThreadsAgrees) {
  // The CG products over the threads (parallel_rows = 0: whatever the size); the same iterates.
  const ShellSetup s(sphere_mesh(MeshFamily::MT1, 2));
  Points g;
  Eigen::SparseMatrix<double> m = s.mass.pattern();
  shell_energy_mass(s.patches, s.bases, s.mass, s.colouring, s.control, 1.0, g, m);
  const int before = omp_get_max_threads();
  int it1 = 0, it2 = 0;
  omp_set_num_threads(1);
  const Eigen::MatrixXd x1 = solve_mass_cg(m, g, 1e-10, 1000, &it1, nullptr, 0);
  omp_set_num_threads(2);
  const Eigen::MatrixXd x2 = solve_mass_cg(m, g, 1e-10, 1000, &it2, nullptr, 0);
  omp_set_num_threads(before);
  EXPECT_EQ(it1, it2);
  EXPECT_LE((x1 - x2).cwiseAbs().maxCoeff(), 1e-13 * x1.cwiseAbs().maxCoeff());
}

TEST(LoopShellAssembly, WarmStartedSolveMeetsTheSameTolerance) {
  const ShellSetup s(sphere_mesh(MeshFamily::MT1, 2));
  Points g;
  Eigen::SparseMatrix<double> m = s.mass.pattern();
  shell_energy_mass(s.patches, s.bases, s.mass, s.colouring, s.control, 1.0, g, m);
  int cold = 0, warm = 0;
  const Eigen::MatrixXd x = solve_mass_cg(m, g, 1e-10, 1000, &cold);
  // A nearby right-hand side from the previous solution: fewer iterations, same residual bound.
  const Eigen::MatrixXd b = 1.001 * Eigen::MatrixXd(g);
  const Eigen::MatrixXd y = solve_mass_cg(m, b, 1e-10, 1000, &warm, &x);
  EXPECT_LT(warm, cold);
  for (int c = 0; c < 3; ++c) EXPECT_LE((b.col(c) - m * y.col(c)).norm(), 1e-10 * b.col(c).norm());
}

TEST(LoopShellAssembly, RepeatedForcesOnOneTopologyAgree) {
  // The second evaluation is warm-started; both meet the CG tolerance, so they agree closely.
  const TriMesh mesh = sphere_mesh(MeshFamily::MT1, 2);
  const Points x = make_rbc(1.0)->map_from_unit_sphere(mesh.positions());
  const auto method = LoopShellMethod::create({});
  Points f1, f2;
  method->forces(mesh.topology(), x, 1.0, f1);
  method->forces(mesh.topology(), x, 1.0, f2);
  EXPECT_LE((f1 - f2).cwiseAbs().maxCoeff(), 1e-8 * f1.cwiseAbs().maxCoeff());
}

}  // namespace
}  // namespace bendlab
