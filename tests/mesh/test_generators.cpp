#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <iostream>
#include <numbers>
#include <set>

#include "bendlab/geometry/measures.hpp"
#include "bendlab/mesh/generators.hpp"

using namespace bendlab;

namespace {

double max_radius_error(const TriMesh& m) {
  double err = 0;
  for (int i = 0; i < m.num_vertices(); ++i) err = std::max(err, std::abs(m.position(i).norm() - 1.0));
  return err;
}

// Every face's normal points away from the origin (the meshes are star-shaped about it).
bool faces_outward(const TriMesh& m) {
  for (int f = 0; f < m.num_faces(); ++f) {
    const Vec3 a = m.position(m.faces()(f, 0)), b = m.position(m.faces()(f, 1)), c = m.position(m.faces()(f, 2));
    if ((b - a).cross(c - a).dot(a + b + c) <= 0) return false;
  }
  return true;
}

void expect_valid_sphere(const TriMesh& m) {
  EXPECT_EQ(m.topology().euler_characteristic(), 2);
  EXPECT_LE(max_radius_error(m), 1e-14);
  EXPECT_TRUE(faces_outward(m));
  // Rebuilding from the raw arrays runs the full validation again.
  EXPECT_NO_THROW(TriMesh(m.positions(), m.faces()));
}

int count_valence(const TriMesh& m, int d) {
  int n = 0;
  for (int i = 0; i < m.num_vertices(); ++i) n += m.topology().valence(i) == d;
  return n;
}

// Convex about the origin: every vertex lies on the inner side of every face plane
// (checked face by face against the vertices of the neighbouring faces, the local condition).
bool locally_convex(const TriMesh& m) {
  const Topology& t = m.topology();
  for (int e = 0; e < t.num_edges(); ++e) {
    const int f0 = t.edge_faces()(e, 0), o1 = t.edge_opposite()(e, 1);
    const Vec3 a = m.position(t.faces()(f0, 0)), b = m.position(t.faces()(f0, 1)), c = m.position(t.faces()(f0, 2));
    const Vec3 n = (b - a).cross(c - a);
    if (n.dot(m.position(o1) - a) >= 0) return false;
  }
  return true;
}

}  // namespace

TEST(GeneratorFamily, ParseAndPrint) {
  EXPECT_EQ(parse_mesh_family("mt1"), MeshFamily::MT1);
  EXPECT_EQ(parse_mesh_family("MT2"), MeshFamily::MT2);
  EXPECT_EQ(parse_mesh_family("Octa"), MeshFamily::Octa);
  EXPECT_THROW(parse_mesh_family("cube"), Error);
  for (MeshFamily f : {MeshFamily::MT1, MeshFamily::MT2, MeshFamily::Octa})
    EXPECT_EQ(parse_mesh_family(to_string(f)), f);
  EXPECT_THROW(sphere_mesh(MeshFamily::MT1, -1), Error);
}

TEST(GeneratorPlatonic, IcosahedronAndOctahedron) {
  const TriMesh ico = icosahedron();
  EXPECT_EQ(ico.num_vertices(), 12);
  EXPECT_EQ(ico.num_faces(), 20);
  expect_valid_sphere(ico);
  EXPECT_EQ(count_valence(ico, 5), 12);
  // Regular: all 30 edges have the same length.
  const Topology& t = ico.topology();
  const double l0 = (ico.position(t.edge_vertices()(0, 0)) - ico.position(t.edge_vertices()(0, 1))).norm();
  for (int e = 0; e < t.num_edges(); ++e)
    EXPECT_NEAR((ico.position(t.edge_vertices()(e, 0)) - ico.position(t.edge_vertices()(e, 1))).norm(), l0, 1e-14);

  const TriMesh oct = octahedron();
  EXPECT_EQ(oct.num_vertices(), 6);
  EXPECT_EQ(oct.num_faces(), 8);
  expect_valid_sphere(oct);
  EXPECT_EQ(count_valence(oct, 4), 6);
}

TEST(GeneratorPlatonic, PolarIcosahedronIsARotation) {
  const TriMesh ico = icosahedron(), polar = icosahedron_polar();
  expect_valid_sphere(polar);
  EXPECT_LT((polar.position(0) - Vec3(0, 0, 1)).norm(), 1e-15);
  EXPECT_LT((polar.position(3) - Vec3(0, 0, -1)).norm(), 1e-15);
  // Same faces, same pairwise distances.
  EXPECT_EQ(polar.faces(), ico.faces());
  for (int i = 0; i < 12; ++i)
    for (int j = 0; j < 12; ++j)
      EXPECT_NEAR((polar.position(i) - polar.position(j)).norm(), (ico.position(i) - ico.position(j)).norm(), 1e-14);
}

TEST(GeneratorFamilies, TriangleCountsAndInvariants) {
  for (MeshFamily fam : {MeshFamily::MT1, MeshFamily::MT2}) {
    for (int k = 0; k <= 6; ++k) {
      const TriMesh m = sphere_mesh(fam, k);
      const int nt = 20 * (1 << (2 * k));
      EXPECT_EQ(m.num_faces(), nt) << to_string(fam) << " level " << k;
      // V - E + F = 2 with E = 3F/2.
      EXPECT_EQ(m.num_vertices(), nt / 2 + 2);
      expect_valid_sphere(m);
      EXPECT_EQ(count_valence(m, 5), 12);
      EXPECT_EQ(count_valence(m, 6), m.num_vertices() - 12);
    }
  }
  const int octa_counts[] = {8, 32, 128, 512, 2048};
  for (int k = 0; k <= 4; ++k) {
    const TriMesh m = sphere_mesh(MeshFamily::Octa, k);
    EXPECT_EQ(m.num_faces(), octa_counts[k]);
    expect_valid_sphere(m);
    EXPECT_EQ(count_valence(m, 4), 6);
    EXPECT_EQ(count_valence(m, 6), m.num_vertices() - 6);
  }
}

TEST(GeneratorRefine, OldVerticesKeepTheirIndices) {
  const TriMesh m1 = sphere_mesh(MeshFamily::MT2, 2);
  const TriMesh m2 = refine_midpoint(m1);
  EXPECT_EQ(m2.positions().topRows(m1.num_vertices()), m1.positions());
  // Each old vertex keeps its valence; every new one has valence 6.
  for (int i = 0; i < m1.num_vertices(); ++i) EXPECT_EQ(m2.topology().valence(i), m1.topology().valence(i));
  // Loop moves the old vertices but keeps them in place in the index order: vertex i of the
  // refined mesh stays the nearest new node to old vertex i.
  const TriMesh m3 = refine_loop(sphere_mesh(MeshFamily::MT1, 2));
  const TriMesh m1b = sphere_mesh(MeshFamily::MT1, 2);
  for (int i = 0; i < m1b.num_vertices(); ++i) EXPECT_LT((m3.position(i) - m1b.position(i)).norm(), 0.05);
}

TEST(GeneratorLoop, RulesWithoutProjection) {
  const TriMesh ico = icosahedron();
  const TriMesh m = refine_loop(ico, false);
  const Topology& t = ico.topology();
  const int n = ico.num_vertices();
  ASSERT_EQ(m.num_vertices(), n + t.num_edges());
  // Every new node is 3/8 (a + b) + 1/8 (c + d) for exactly one old edge (a, b) with opposite
  // vertices c, d; search by position, without relying on the edge numbering.
  for (int e = 0; e < t.num_edges(); ++e) {
    const Vec3 expected = 3.0 / 8.0 * (ico.position(t.edge_vertices()(e, 0)) + ico.position(t.edge_vertices()(e, 1))) +
                          1.0 / 8.0 * (ico.position(t.edge_opposite()(e, 0)) + ico.position(t.edge_opposite()(e, 1)));
    int hits = 0;
    for (int i = n; i < m.num_vertices(); ++i) hits += (m.position(i) - expected).norm() < 1e-14;
    EXPECT_EQ(hits, 1) << "edge " << e;
  }
  // Old vertices of valence 5: beta = (5/8 - (3/8 + cos(2 pi/5)/4)^2)/5. On the regular
  // icosahedron the neighbours sum to s * v (by symmetry), with s = 5 (v . w) for a neighbour w.
  const double c = 3.0 / 8.0 + std::cos(2.0 * std::numbers::pi / 5.0) / 4.0;
  const double beta = (5.0 / 8.0 - c * c) / 5.0;
  for (int i = 0; i < n; ++i) {
    Vec3 sum = Vec3::Zero();
    for (int k = t.ring_begin(i); k < t.ring_end(i); ++k) sum += ico.position(t.ring_vertices()[k]);
    const Vec3 expected = (1.0 - 5.0 * beta) * ico.position(i) + beta * sum;
    EXPECT_LT((m.position(i) - expected).norm(), 1e-14);
    // It moved inward, along its own direction.
    EXPECT_LT(m.position(i).norm(), 1.0);
    EXPECT_LT(m.position(i).normalized().cross(ico.position(i)).norm(), 1e-14);
  }
  // Midpoint refinement without projection keeps the old vertices and puts the new ones at midpoints.
  const TriMesh mid = refine_midpoint(ico, false);
  EXPECT_EQ(mid.positions().topRows(n), ico.positions());
  for (int i = n; i < mid.num_vertices(); ++i) EXPECT_LT(mid.position(i).norm(), 1.0);
}

TEST(GeneratorLoop, UnprojectedLimitShrinksButStaysConvex) {
  TriMesh m = icosahedron();
  double r_max_prev = 1.0;
  for (int k = 0; k < 4; ++k) {
    m = refine_loop(m, false);
    double r_max = 0;
    for (int i = 0; i < m.num_vertices(); ++i) r_max = std::max(r_max, m.position(i).norm());
    // Loop's scheme is an averaging: every node is a convex combination of the previous ones,
    // and the surface contracts towards the limit surface inside the icosahedron.
    EXPECT_LT(r_max, r_max_prev);
    r_max_prev = r_max;
    EXPECT_TRUE(locally_convex(m)) << "step " << k + 1;
    EXPECT_GT(enclosed_volume(m.topology(), m.positions()), 0);
  }
}

TEST(GeneratorFamilies, Mt1AndMt2Differ) {
  const TriMesh a = sphere_mesh(MeshFamily::MT1, 2), b = sphere_mesh(MeshFamily::MT2, 2);
  ASSERT_EQ(a.faces(), b.faces());  // same connectivity by construction
  // The 12 icosahedron vertices are fixed points of both (symmetry), the others are not.
  EXPECT_LT((a.positions().topRows(12) - b.positions().topRows(12)).cwiseAbs().maxCoeff(), 1e-14);
  EXPECT_GT((a.positions() - b.positions()).rowwise().norm().maxCoeff(), 1e-3);
}

TEST(GeneratorFamilies, MeanEdgeLengthHalvesPerLevel) {
  // From the icosahedron itself the ratio is larger (about 0.55): projecting 42 nodes onto the
  // sphere stretches the chords noticeably. From the 80-triangle mesh on, each level halves h
  // to within a few per cent, approaching 1/2 as the chords approach arcs.
  TriMesh m = sphere_mesh(MeshFamily::MT1, 1);
  double prev = mean_edge_length(m.topology(), m.positions());
  double prev_dev = 1.0;
  for (int k = 2; k <= 6; ++k) {
    m = refine_loop(m);
    const double h = mean_edge_length(m.topology(), m.positions());
    EXPECT_NEAR(h / prev, 0.5, 0.03) << "level " << k;
    EXPECT_LT(std::abs(h / prev - 0.5), prev_dev) << "level " << k;
    prev_dev = std::abs(h / prev - 0.5);
    prev = h;
  }
}

TEST(GeneratorFamilies, Level6HasThePapersLargestSize) {
  // The 81920-triangle mesh of the paper's largest study; how long it takes to build is measured
  // by bench_geometry (BM_SphereMeshBuild), never asserted here.
  const TriMesh m = sphere_mesh(MeshFamily::MT1, 6);
  EXPECT_EQ(m.num_faces(), 81920);
  EXPECT_EQ(m.num_vertices(), 40962);
}

TEST(GeneratorRivara, OnePassSplitsEveryTriangle) {
  for (MeshFamily fam : {MeshFamily::MT1, MeshFamily::MT2}) {
    const TriMesh m0 = sphere_mesh(fam, 2);
    const TriMesh m1 = rivara_pass(m0);
    expect_valid_sphere(m1);
    EXPECT_GE(m1.num_faces(), 2 * m0.num_faces());
    // Old nodes keep their indices and positions; the new ones are edge midpoints.
    EXPECT_EQ(m1.positions().topRows(m0.num_vertices()), m0.positions());
    // Every original triangle was split: no face of the start survives unchanged.
    std::set<std::array<int, 3>> old_faces;
    for (int f = 0; f < m0.num_faces(); ++f) {
      std::array<int, 3> key{m0.faces()(f, 0), m0.faces()(f, 1), m0.faces()(f, 2)};
      std::sort(key.begin(), key.end());
      old_faces.insert(key);
    }
    for (int f = 0; f < m1.num_faces(); ++f) {
      std::array<int, 3> key{m1.faces()(f, 0), m1.faces()(f, 1), m1.faces()(f, 2)};
      std::sort(key.begin(), key.end());
      EXPECT_EQ(old_faces.count(key), 0u);
    }
    // Bisection keeps the total area of the flat parents when the midpoints are not projected.
    const TriMesh flat = rivara_pass(m0, false);
    EXPECT_NEAR(surface_area(flat.topology(), flat.positions()), surface_area(m0.topology(), m0.positions()), 1e-12);
    EXPECT_EQ(flat.faces(), m1.faces());
  }
}

TEST(GeneratorRivara, ThreePassesFromThe320Meshes) {
  for (MeshFamily fam : {MeshFamily::MT1, MeshFamily::MT2}) {
    const TriMesh m0 = sphere_mesh(fam, 2);
    const double angle0 = min_corner_angle(m0.topology(), m0.positions());
    TriMesh m = m0;
    for (int p = 1; p <= 3; ++p) {
      const int before = m.num_faces();
      m = rivara_pass(m);
      expect_valid_sphere(m);
      EXPECT_GE(m.num_faces(), 2 * before);
      // Rivara's bound: the smallest angle stays above half the initial smallest angle.
      EXPECT_GT(min_corner_angle(m.topology(), m.positions()), 0.5 * angle0);
      std::cout << "[ info ] " << to_string(fam) << " 320 + " << p << " Rivara passes: " << m.num_faces()
                << " triangles, " << m.num_vertices() << " nodes, valence " << valence_stats(m.topology()).min
                << ".." << valence_stats(m.topology()).max << "\n";
    }
    const TriMesh again = sphere_mesh(fam, 2, 3);
    EXPECT_EQ(again.faces(), m.faces());
    EXPECT_EQ(again.positions(), m.positions());
    ::testing::Test::RecordProperty(to_string(fam) + "_rivara3_triangles", m.num_faces());
  }
}

TEST(GeneratorLevels, LevelWithTrianglesInvertsTheCount) {
  for (int k = 0; k <= 6; ++k) {
    EXPECT_EQ(level_with_triangles(MeshFamily::MT1, 20L << (2 * k)), k);
    EXPECT_EQ(level_with_triangles(MeshFamily::Octa, 8L << (2 * k)), k);
  }
  EXPECT_EQ(level_with_triangles(MeshFamily::MT2, 1000), -1);
  EXPECT_EQ(level_with_triangles(MeshFamily::Octa, 320), -1);
}
