// Loop and midpoint subdivision as topology + sparse stencil (mesh/subdivision.hpp), and the sphere
// generators built on them.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "bendlab/mesh/generators.hpp"
#include "bendlab/mesh/subdivision.hpp"

using namespace bendlab;

namespace {

// The refinement as the generators computed it before the stencil had its own file (kept here
// verbatim as the reference): Loop's rules in factored form, or midpoints, then optional
// projection, and the 1 -> 4 split.
TriMesh reference_refine(const TriMesh& mesh, bool loop, bool project) {
  const Topology& t = mesh.topology();
  const Points& x = mesh.positions();
  const int n = t.num_vertices(), ne = t.num_edges();
  Points y(n + ne, 3);
  const IndexPairs& ev = t.edge_vertices();
  const IndexPairs& eo = t.edge_opposite();
  if (loop) {
    for (int i = 0; i < n; ++i) {
      const int d = t.valence(i);
      const double c = 3.0 / 8.0 + std::cos(2.0 * std::numbers::pi / d) / 4.0;
      const double beta = (5.0 / 8.0 - c * c) / d;
      Vec3 sum = Vec3::Zero();
      for (int k = t.ring_begin(i); k < t.ring_end(i); ++k) sum += row(x, t.ring_vertices()[k]);
      y.row(i) = ((1.0 - d * beta) * row(x, i) + beta * sum).transpose();
    }
    for (int e = 0; e < ne; ++e)
      y.row(n + e) =
          3.0 / 8.0 * (x.row(ev(e, 0)) + x.row(ev(e, 1))) + 1.0 / 8.0 * (x.row(eo(e, 0)) + x.row(eo(e, 1)));
    if (project)
      for (Eigen::Index i = 0; i < y.rows(); ++i) y.row(i).normalize();
  } else {
    y.topRows(n) = x;
    for (int e = 0; e < ne; ++e) y.row(n + e) = 0.5 * (x.row(ev(e, 0)) + x.row(ev(e, 1)));
    if (project)
      for (Eigen::Index i = n; i < y.rows(); ++i) y.row(i).normalize();
  }
  const Faces& f = t.faces();
  const Faces& fe = t.face_edges();
  Faces out(4 * f.rows(), 3);
  for (Eigen::Index i = 0; i < f.rows(); ++i) {
    const int a = f(i, 0), b = f(i, 1), c = f(i, 2);
    const int m_bc = n + fe(i, 0), m_ca = n + fe(i, 1), m_ab = n + fe(i, 2);
    out.row(4 * i + 0) << a, m_ab, m_ca;
    out.row(4 * i + 1) << b, m_bc, m_ab;
    out.row(4 * i + 2) << c, m_ca, m_bc;
    out.row(4 * i + 3) << m_ab, m_bc, m_ca;
  }
  return TriMesh(std::move(y), out);
}

void expect_identical(const TriMesh& a, const TriMesh& b) {
  ASSERT_EQ(a.num_vertices(), b.num_vertices());
  ASSERT_EQ(a.num_faces(), b.num_faces());
  EXPECT_TRUE(a.faces() == b.faces());
  EXPECT_TRUE(a.positions() == b.positions()) << "positions must be bit-identical";
}

}  // namespace

TEST(Subdivision, GeneratorsAreBitIdenticalToTheDirectRules) {
  for (const MeshFamily fam : {MeshFamily::MT1, MeshFamily::MT2, MeshFamily::Octa}) {
    TriMesh ref = fam == MeshFamily::Octa ? octahedron() : icosahedron();
    for (int level = 1; level <= 4; ++level) {
      ref = reference_refine(ref, fam == MeshFamily::MT1, true);
      expect_identical(sphere_mesh(fam, level), ref);
    }
  }
  // Without projection too.
  const TriMesh ico = icosahedron();
  expect_identical(refine_loop(ico, false), reference_refine(ico, true, false));
  expect_identical(refine_midpoint(ico, false), reference_refine(ico, false, false));
}

TEST(Subdivision, StencilAppliedToThePositionsGivesTheRefinedMesh) {
  const TriMesh m = sphere_mesh(MeshFamily::MT1, 2);
  const Topology& t = m.topology();
  const Points& x = m.positions();
  const SubdivisionStep loop = loop_subdivision(t);
  const SubdivisionStep mid = midpoint_subdivision(t);
  for (const SubdivisionStep* s : {&loop, &mid}) {
    ASSERT_EQ(s->stencil.rows(), t.num_vertices() + t.num_edges());
    ASSERT_EQ(s->stencil.cols(), t.num_vertices());
    EXPECT_EQ(s->topology->num_faces(), 4 * t.num_faces());
    EXPECT_TRUE(s->topology->faces() == refine_loop(m, false).faces());
    // Affine invariance: every row sums to 1.
    const Eigen::VectorXd sums = s->stencil * Eigen::VectorXd::Ones(t.num_vertices());
    EXPECT_LT((sums.array() - 1.0).abs().maxCoeff(), 1e-15);
  }
  // Loop: equal to the factored rules up to rounding; midpoint: bit for bit.
  const Points fine_loop = loop.stencil * x;
  EXPECT_LT((fine_loop - loop_positions(t, x)).cwiseAbs().maxCoeff(), 1e-15);
  EXPECT_LT((fine_loop - refine_loop(m, false).positions()).cwiseAbs().maxCoeff(), 1e-15);
  const Points fine_mid = mid.stencil * x;
  EXPECT_TRUE(fine_mid == midpoint_positions(t, x));
  EXPECT_TRUE(fine_mid == refine_midpoint(m, false).positions());
  // Loop's weights at a regular vertex (valence 6): beta = 1/16, centre 5/8; an edge row has
  // 3/8, 3/8, 1/8, 1/8.
  for (int i = 0; i < t.num_vertices(); ++i) {
    if (t.valence(i) != 6) continue;
    EXPECT_NEAR(loop.stencil.coeff(i, i), 5.0 / 8.0, 1e-15);
    EXPECT_NEAR(loop.stencil.coeff(i, t.ring_vertices()[t.ring_begin(i)]), 1.0 / 16.0, 1e-15);
    EXPECT_EQ(loop.stencil.row(i).nonZeros(), 7);
    break;
  }
  const int e = 5, n = t.num_vertices();
  EXPECT_EQ(loop.stencil.coeff(n + e, t.edge_vertices()(e, 0)), 3.0 / 8.0);
  EXPECT_EQ(loop.stencil.coeff(n + e, t.edge_opposite()(e, 1)), 1.0 / 8.0);
  EXPECT_EQ(mid.stencil.coeff(n + e, t.edge_vertices()(e, 1)), 0.5);
  EXPECT_THROW(loop_positions(t, Points::Zero(3, 3)), Error);
}
