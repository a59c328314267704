#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "bendlab/mesh/generators.hpp"
#include "bendlab/mesh/jitter.hpp"
#include "bendlab/mesh/mesh_spec.hpp"

using namespace bendlab;

namespace {

// Standard deviation of the edge lengths divided by their mean.
double relative_edge_spread(const TriMesh& m) {
  const Topology& t = m.topology();
  Scalars len(t.num_edges());
  for (int e = 0; e < t.num_edges(); ++e)
    len[e] = (m.position(t.edge_vertices()(e, 0)) - m.position(t.edge_vertices()(e, 1))).norm();
  const double mean = len.mean();
  return std::sqrt((len.array() - mean).square().mean()) / mean;
}

// The angle of each node's step in its tangent basis (the basis of jitter.hpp: t1 from the
// coordinate axis least aligned with the node).
Scalars step_angles(const TriMesh& sphere, std::uint64_t seed) {
  const Points y = jitter_tangential(sphere, 0.25, seed);
  Scalars phi(sphere.num_vertices());
  for (int i = 0; i < sphere.num_vertices(); ++i) {
    const Vec3 x = sphere.position(i), d = y.row(i).transpose() - x;
    int k = 0;
    for (int j = 1; j < 3; ++j)
      if (std::abs(x[j]) < std::abs(x[k])) k = j;
    const Vec3 t1 = x.cross(Vec3::Unit(k)).normalized(), t2 = x.cross(t1).normalized();
    phi[i] = std::atan2(d.dot(t2), d.dot(t1));
  }
  return phi;
}

}  // namespace

TEST(Jitter, SameSeedSameMeshOtherSeedOrLevelOtherPattern) {
  const TriMesh mt1 = sphere_mesh(MeshFamily::MT1, 3);
  const TriMesh a = jitter_sphere(mt1, 0.25, 7), b = jitter_sphere(mt1, 0.25, 7), c = jitter_sphere(mt1, 0.25, 8);
  EXPECT_EQ(a.positions(), b.positions());  // bit for bit
  EXPECT_GT((a.positions() - c.positions()).cwiseAbs().maxCoeff(), 1e-3);
  EXPECT_EQ(a.faces(), mt1.faces());
  // The family: level k uses seed 28 + k, so neighbouring levels do not repeat the pattern of
  // directions on the nodes they share (the first 642 nodes of level 4 descend from level 3's).
  const TriMesh l3 = sphere_mesh(MeshFamily::Irregular, 3);
  EXPECT_EQ(l3.positions(), irregular_sphere_mesh(3, kDefaultJitterFraction, kDefaultJitterSeed).positions());
  EXPECT_EQ(l3.positions(), jitter_sphere(mt1, 0.25, kDefaultJitterSeed + 3).positions());
  const TriMesh mt1_4 = sphere_mesh(MeshFamily::MT1, 4);
  EXPECT_EQ(sphere_mesh(MeshFamily::Irregular, 4).positions(),
            jitter_sphere(mt1_4, 0.25, kDefaultJitterSeed + 4).positions());
  const Scalars phi3 = step_angles(mt1, kDefaultJitterSeed + 3);
  const Scalars phi4 = step_angles(mt1_4, kDefaultJitterSeed + 4).head(mt1.num_vertices());
  EXPECT_GT((phi3 - phi4).cwiseAbs().maxCoeff(), 1.0);
  EXPECT_EQ(mesh_from_spec("irregular:1280").positions(), l3.positions());
  EXPECT_EQ(parse_mesh_family("Irregular"), MeshFamily::Irregular);
  EXPECT_EQ(to_string(MeshFamily::Irregular), "irregular");
  EXPECT_EQ(level_with_triangles(MeshFamily::Irregular, 81920), 6);
}

TEST(Jitter, TangentialStepIsTheFractionOfTheMeanEdgeLength) {
  const TriMesh mt1 = sphere_mesh(MeshFamily::MT1, 3);
  const Scalars l = mean_incident_edge_length(mt1);
  for (double fraction : {0.0, 0.1, 0.25, 0.4}) {
    const Points y = jitter_tangential(mt1, fraction, 5);
    for (int i = 0; i < mt1.num_vertices(); ++i) {
      const Vec3 x = mt1.position(i), d = y.row(i).transpose() - x;
      EXPECT_NEAR(d.norm(), fraction * l[i], 1e-15) << i;
      EXPECT_NEAR(d.dot(x), 0.0, 1e-15) << i;  // in the tangent plane
    }
  }
  // The mean incident edge length of a node of valence 5 of the icosahedron: its edge.
  const TriMesh ico = icosahedron();
  const double edge = (ico.position(0) - ico.position(11)).norm();
  EXPECT_NEAR(mean_incident_edge_length(ico)[0], edge, 1e-15);
}

TEST(Jitter, DirectionsCoverTheTangentPlane) {
  // The angles are uniform in [0, 2 pi): the mean of cos and sin of the angle tends to zero like
  // 1/sqrt(2 N); with N = 10242 nodes four standard deviations are 0.028.
  const Scalars phi = step_angles(sphere_mesh(MeshFamily::MT1, 5), kDefaultJitterSeed);
  EXPECT_LT(std::abs(phi.array().cos().mean()), 0.028);
  EXPECT_LT(std::abs(phi.array().sin().mean()), 0.028);
  // Every quarter of the circle is drawn about as often (a quarter each, +- 4 standard deviations).
  for (int q = 0; q < 4; ++q) {
    const double lo = -M_PI + q * M_PI / 2, share = ((phi.array() >= lo) && (phi.array() < lo + M_PI / 2)).cast<double>().mean();
    EXPECT_NEAR(share, 0.25, 4 * std::sqrt(0.25 * 0.75 / phi.size())) << q;
  }
}

TEST(Jitter, NodesOnTheSphereAndTrianglesOutward) {
  for (int level = 0; level <= 5; ++level) {
    const TriMesh m = sphere_mesh(MeshFamily::Irregular, level);
    for (int i = 0; i < m.num_vertices(); ++i) EXPECT_NEAR(m.position(i).norm(), 1.0, 1e-15) << level << " " << i;
    EXPECT_EQ(first_folded_face(m.faces(), m.positions()), -1) << level;
  }
}

TEST(Jitter, StaysIrregularUnderRefinement) {
  // A step of a l in a uniform direction at both ends changes an edge of length l by
  // a l (cos p - cos q) to first order, whose standard deviation is a l: the relative spread of
  // the edge lengths stays near a at every level, while MT1's own spread shrinks.
  double first = 0;
  for (int level = 2; level <= 5; ++level) {
    const double spread = relative_edge_spread(sphere_mesh(MeshFamily::Irregular, level));
    EXPECT_GT(spread, kDefaultJitterFraction / 2) << level;
    EXPECT_GT(spread, 3 * relative_edge_spread(sphere_mesh(MeshFamily::MT1, level))) << level;
    if (level == 2) first = spread;
    EXPECT_GT(spread, 0.9 * first) << level;  // does not shrink
  }
}

TEST(Jitter, FoldsAreRefused) {
  const TriMesh mt1 = sphere_mesh(MeshFamily::MT1, 3);
  // A step of a whole mean edge length crosses the neighbours' edges.
  try {
    jitter_sphere(mt1, 1.0, 7);
    FAIL() << "a fraction of 1 did not fold";
  } catch (const Error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("jitter fraction 1 folds triangle"), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
  EXPECT_THROW(irregular_sphere_mesh(3, 1.0), Error);
  EXPECT_THROW(jitter_sphere(mt1, -0.1, 7), Error);
  EXPECT_THROW(jitter_sphere(mt1, NAN, 7), Error);
  // first_folded_face: a face turned inward, and a degenerate face.
  Faces f = mt1.faces();
  EXPECT_EQ(first_folded_face(f, mt1.positions()), -1);
  std::swap(f(5, 1), f(5, 2));
  EXPECT_EQ(first_folded_face(f, mt1.positions()), 5);
  Points x(4, 3);
  x << 1, 0, 0, 0, 1, 0, 0, 0, 1, -1, 0, 0;
  Faces g(2, 3);
  g << 0, 1, 2, 0, 1, 2;
  EXPECT_EQ(first_folded_face(g, x), -1);  // normal (1, 1, 1): outward
  g << 0, 1, 2, 0, 1, 3;
  x.row(3) << 2, -1, 0;  // on the line through nodes 0 and 1: triangle 1 is degenerate
  EXPECT_EQ(first_folded_face(g, x), 1);
}
