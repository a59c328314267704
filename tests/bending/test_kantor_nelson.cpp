// Method A (Kantor-Nelson, eq. (6)): the force is the exact gradient of the energy, the energy
// and force obey the symmetries of the model, and the energy has the values the dihedral-angle
// formula gives on meshes where it can be evaluated by hand.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "bendlab/bending/kantor_nelson.hpp"
#include "bendlab/geometry/measures.hpp"
#include "bendlab/geometry/mesh_geometry.hpp"
#include "bendlab/mesh/generators.hpp"
#include "bendlab/surfaces/analytic_surface.hpp"
#include "bending/energy_test_support.hpp"

using namespace bendlab;
using namespace bendlab::test_support;

namespace {

// A unit cube, each square split into two triangles along a diagonal: the 6 diagonals are
// edges between coplanar triangles (theta = 0 exactly), the 12 cube edges have theta = pi/2.
TriMesh split_cube() {
  Points x(8, 3);
  x << 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1;
  Faces f(12, 3);
  f << 0, 2, 1, 0, 3, 2,  // z = 0, outward -z
      4, 5, 6, 4, 6, 7,   // z = 1
      0, 1, 5, 0, 5, 4,   // y = 0
      3, 7, 6, 3, 6, 2,   // y = 1
      0, 4, 7, 0, 7, 3,   // x = 0
      1, 2, 6, 1, 6, 5;   // x = 1
  return TriMesh(x, f);
}

// Eq. (6) evaluated directly from the face normals of MeshGeometry, edge by edge.
double reference_energy(const TriMesh& mesh, bool small_angle) {
  const MeshGeometry g = MeshGeometry::compute(mesh.topology(), mesh.positions());
  const IndexPairs& ef = mesh.topology().edge_faces();
  double E = 0;
  for (int e = 0; e < ef.rows(); ++e) {
    const double c = std::clamp(g.face_normal.row(ef(e, 0)).dot(g.face_normal.row(ef(e, 1))), -1.0, 1.0);
    const double theta = std::acos(c);
    E += small_angle ? std::sqrt(3.0) * theta * theta : 2 * std::sqrt(3.0) * (1 - c);
  }
  return E;
}

double mean_force_density(const BendingResult& r) {
  return r.force_density.rowwise().norm().mean();
}

}  // namespace

TEST(KantorNelson, CreateParsesOptions) {
  EXPECT_FALSE(dynamic_cast<KantorNelson&>(*KantorNelson::create({})).small_angle());
  EXPECT_TRUE(dynamic_cast<KantorNelson&>(*KantorNelson::create({{"small_angle", "true"}})).small_angle());
  EXPECT_FALSE(dynamic_cast<KantorNelson&>(*KantorNelson::create({{"small_angle", "0"}})).small_angle());
  EXPECT_THROW(KantorNelson::create({{"small_angle", "maybe"}}), Error);
  EXPECT_THROW(KantorNelson::create({{"rings", "2"}}), Error);
  EXPECT_EQ(KantorNelson().name(), "A");
}

// The regular icosahedron: 30 edges, angle between neighbouring face normals acos(sqrt(5)/3).
TEST(KantorNelson, IcosahedronEnergyIsExact) {
  const TriMesh m = icosahedron();
  const double c = std::sqrt(5.0) / 3.0, kB = 2.5;
  EXPECT_NEAR(*KantorNelson().energy(m.topology(), m.positions(), kB), 30 * 2 * std::sqrt(3.0) * kB * (1 - c), 1e-12);
  const double theta = std::acos(c);
  EXPECT_NEAR(*KantorNelson(true).energy(m.topology(), m.positions(), kB), 30 * std::sqrt(3.0) * kB * theta * theta,
              1e-12);
  // By symmetry every node force is radial with the same magnitude; moving every node radially
  // by the same amount is a scaling, which leaves E unchanged, so that magnitude is zero.
  Points F;
  KantorNelson().forces(m.topology(), m.positions(), kB, F);
  EXPECT_LT(F.norm(), 1e-13 * kB);
}

TEST(KantorNelson, EnergyMatchesDirectEvaluationOfEq6) {
  for (const TriMesh& m : {perturbed_sphere(2, 0.1), rivara_rbc()}) {
    for (bool small : {false, true}) {
      const double E = *KantorNelson(small).energy(m.topology(), m.positions(), 1.0);
      EXPECT_NEAR(E, reference_energy(m, small), 1e-11 * E);
      EXPECT_NEAR(*KantorNelson(small).compute(m.topology(), m.positions(), 1.0).energy, E, 1e-11 * E);
    }
  }
}

TEST(KantorNelson, ForceIsMinusEnergyGradientOnPerturbedSphere) {
  const TriMesh m = perturbed_sphere(2, 0.1);
  expect_force_is_minus_gradient(KantorNelson(false), m);
  expect_force_is_minus_gradient(KantorNelson(true), m);
}

TEST(KantorNelson, ForceIsMinusEnergyGradientOnRivaraRbc) {
  const TriMesh m = rivara_rbc();
  expect_force_is_minus_gradient(KantorNelson(false), m);
  expect_force_is_minus_gradient(KantorNelson(true), m);
}

TEST(KantorNelson, TranslationRotationAndScaleInvariance) {
  for (const TriMesh& m : {perturbed_sphere(2, 0.1), rivara_rbc()}) {
    for (bool small : {false, true}) {
      expect_translation_and_rotation_invariance(KantorNelson(small), m);
      expect_rigid_and_scale_behaviour(KantorNelson(small), m);
    }
  }
}

// Coplanar neighbours (theta = 0, sin theta = 0): the force stays finite and, for the
// small-angle form whose derivative carries theta / sin theta, still equals -grad E (the
// finite-difference steps cross theta = 0).
TEST(KantorNelson, FlatEdgesGiveFiniteExactForces) {
  const TriMesh cube = split_cube();
  const double kt = std::sqrt(3.0);
  EXPECT_NEAR(*KantorNelson().energy(cube.topology(), cube.positions(), 1.0), 12 * 2 * kt, 1e-12);
  EXPECT_NEAR(*KantorNelson(true).energy(cube.topology(), cube.positions(), 1.0), 12 * kt * M_PI * M_PI / 4, 1e-12);
  for (bool small : {false, true}) {
    const BendingResult r = KantorNelson(small).compute(cube.topology(), cube.positions(), 1.0);
    EXPECT_TRUE(r.force.allFinite());
    EXPECT_TRUE(r.force_density.allFinite());
    expect_force_is_minus_gradient(KantorNelson(small), cube);
  }
  // Moving corner 0 by 1e-9 out of the plane x = 0 makes the diagonal 0-7 nearly flat
  // (theta ~ 1e-9, on the series branch of theta / sin theta): the force is continuous there.
  Points x = cube.positions();
  Points F0, F1;
  KantorNelson(true).forces(cube.topology(), x, 1.0, F0);
  x(0, 0) += 1e-9;
  KantorNelson(true).forces(cube.topology(), x, 1.0, F1);
  EXPECT_LT((F1 - F0).norm(), 1e-7 * F0.norm());
}

// 0 <= theta^2 - 2 (1 - cos theta) <= theta^4 / 12, so the two energies differ by at most
// theta_max^2 / 12 relative, which vanishes as the mesh is refined.
TEST(KantorNelson, SmallAngleApproachesStandardForm) {
  double previous = INFINITY;
  for (int level = 2; level <= 4; ++level) {
    const TriMesh m = rivara_pass(sphere_mesh(MeshFamily::MT1, level));
    const TriMesh rbc = m.with_positions(make_rbc()->map_from_unit_sphere(m.positions()));
    const MeshGeometry g = MeshGeometry::compute(rbc.topology(), rbc.positions());
    double theta_max = 0;
    const IndexPairs& ef = rbc.topology().edge_faces();
    for (int e = 0; e < ef.rows(); ++e)
      theta_max = std::max(theta_max, std::acos(std::min(1.0, g.face_normal.row(ef(e, 0)).dot(g.face_normal.row(ef(e, 1))))));
    const double Es = *KantorNelson(false).energy(rbc.topology(), rbc.positions(), 1.0);
    const double Ea = *KantorNelson(true).energy(rbc.topology(), rbc.positions(), 1.0);
    const double rel = (Ea - Es) / Es;
    EXPECT_GE(rel, 0.0);
    EXPECT_LE(rel, theta_max * theta_max / 12);
    EXPECT_LT(rel, previous);
    previous = rel;
    // The force differs by the factor theta / sin theta - 1 <= theta_max^2 / 6 (1 + ...) per edge term.
    Points Fs, Fa;
    KantorNelson(false).forces(rbc.topology(), rbc.positions(), 1.0, Fs);
    KantorNelson(true).forces(rbc.topology(), rbc.positions(), 1.0, Fa);
    EXPECT_LT((Fa - Fs).norm() / Fs.norm(), theta_max * theta_max / 5);
  }
  EXPECT_LT(previous, 1e-3);
}

// E on refined spheres approaches a constant that depends on the triangulation. With
// kB~ = sqrt(3) kB a tiling by equilateral triangles gives 8 pi kB (see kantor_nelson.hpp). The
// Loop-smoothed MT1 triangles are close to equilateral and E approaches 8 pi from above to within
// 0.2%; the octahedron family, whose triangles have corners near 90 degrees at the six valence-4
// nodes, stays more than 20% above 8 pi: kB~ = sqrt(3) kB is not a property of the surface alone.
TEST(KantorNelson, SphereEnergyConvergesToATriangulationDependentLimit) {
  std::vector<double> E;
  for (int level = 1; level <= 5; ++level) {
    const TriMesh m = sphere_mesh(MeshFamily::MT1, level);
    E.push_back(*KantorNelson().energy(m.topology(), m.positions(), 1.0));
    EXPECT_GT(E.back(), 8 * M_PI);
  }
  // From level 2 on the corrections shrink (by a factor of about 4 per level, O(h^2)).
  for (size_t k = 2; k < E.size(); ++k) EXPECT_LT(std::abs(E[k] - E[k - 1]), 0.5 * std::abs(E[k - 1] - E[k - 2]));
  EXPECT_LT(E.back(), 1.01 * 8 * M_PI);
  const TriMesh octa = sphere_mesh(MeshFamily::Octa, 4);
  EXPECT_GT(*KantorNelson().energy(octa.topology(), octa.positions(), 1.0), 1.2 * 8 * M_PI);
}

TEST(KantorNelson, ComputeFillsEveryField) {
  const TriMesh m = rivara_rbc();
  const BendingResult r = KantorNelson().compute(m.topology(), m.positions(), 1.0);
  const MeshGeometry g = MeshGeometry::compute(m.topology(), m.positions());
  Points F;
  KantorNelson().forces(m.topology(), m.positions(), 1.0, F);
  EXPECT_EQ(r.force, F);
  EXPECT_EQ(r.area, g.mixed_area);
  EXPECT_EQ(r.normal, g.normal_mwa);
  for (int i = 0; i < m.num_vertices(); ++i) {
    EXPECT_NEAR((r.force_density.row(i) * r.area[i] - r.force.row(i)).norm(), 0.0, 1e-14 * r.force.row(i).norm());
    EXPECT_TRUE(std::isnan(r.H[i]) && std::isnan(r.K[i]) && std::isnan(r.lapH[i]));
  }
}

// The exact force density on a sphere is zero. The node forces of Method A shrink with
// resolution, but more slowly than the mixed areas (~h^2) they are divided by: the mean |f| on
// MT1 spheres grows as the mesh is refined, and its maximum (at the valence-5 nodes) grows like
// 1/h^2, as the paper reports for the RBC (section 3).
TEST(KantorNelson, SphereNodeForcesShrinkButForceDensityDoesNot) {
  double previous_F = INFINITY, previous_f = 0;
  for (int level = 2; level <= 5; ++level) {
    const TriMesh m = sphere_mesh(MeshFamily::MT1, level);
    const BendingResult r = KantorNelson().compute(m.topology(), m.positions(), 1.0);
    const double mean_F = r.force.rowwise().norm().mean(), mean_f = mean_force_density(r);
    EXPECT_LT(mean_F, previous_F);
    EXPECT_GT(mean_f, previous_f);
    previous_F = mean_F;
    previous_f = mean_f;
  }
}
