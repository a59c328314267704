// The signed distance to a mesh behind cell growth (cell_growth.hpp), against every triangle
// tried in turn and the winding number, for a red blood cell of eq. (15) at R = 3.91 um.
#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <random>

#include "bendlab/geometry/point_in_mesh.hpp"
#include "bendlab/mesh/generators.hpp"
#include "bendlab/suspension/cell_growth.hpp"
#include "bendlab/surfaces/analytic_surface.hpp"

using namespace bendlab;

namespace {

// The distance from p to triangle (a, b, c), found apart from MeshDistance's regions: the foot
// on the plane if it falls inside (barycentric weights from areas), else the nearest edge.
double triangle_distance(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  // The plane's foot, if it falls inside the triangle.
  const Vec3 n = (b - a).cross(c - a);
  const Vec3 foot = p - n * (n.dot(p - a) / n.squaredNorm());
  const double A = n.norm();
  const double wa = (b - foot).cross(c - foot).dot(n) / (A * A), wb = (c - foot).cross(a - foot).dot(n) / (A * A);
  double best = std::numeric_limits<double>::infinity();
  if (wa >= 0 && wb >= 0 && wa + wb <= 1) best = (p - foot).norm();
  const Vec3 ends[3][2] = {{a, b}, {b, c}, {c, a}};
  for (const auto& e : ends) {
    const Vec3 d = e[1] - e[0];
    const double t = std::clamp(d.dot(p - e[0]) / d.squaredNorm(), 0.0, 1.0);
    best = std::min(best, (p - (e[0] + t * d)).norm());
  }
  return best;
}

}  // namespace

TEST(MeshDistance, EqualsTheNearestTriangleAndKnowsInsideFromOutside) {
  const TriMesh s = sphere_mesh(MeshFamily::MT1, 2);
  const TriMesh cell = s.with_positions(make_rbc(3.91)->map_from_unit_sphere(s.positions()));
  const Points& x = cell.positions();
  const Faces& F = cell.topology().faces();
  const double band = 0.6;
  const MeshDistance distance(cell.topology(), x, band);
  const BoundingBox box = bounding_box(x);
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  int near = 0, inside = 0;
  for (int k = 0; k < 1500; ++k) {
    Vec3 p;
    for (int d = 0; d < 3; ++d) p[d] = box.lo[d] - 1.0 + (box.hi[d] - box.lo[d] + 2.0) * u(rng);
    double exact = std::numeric_limits<double>::infinity();
    for (Eigen::Index f = 0; f < F.rows(); ++f) exact = std::min(exact, triangle_distance(p, row(x, F(f, 0)), row(x, F(f, 1)), row(x, F(f, 2))));
    const bool in = contains(cell.topology(), x, box, p);
    MeshDistance::Hit hit;
    const bool found = distance.query(p, hit);
    if (in || exact < band - 1e-9) {
      ASSERT_TRUE(found) << "point " << k << " at " << exact << (in ? " inside" : " outside");
      EXPECT_NEAR(std::abs(hit.distance), exact, 1e-9) << "point " << k;
      EXPECT_EQ(hit.distance < 0, in) << "point " << k << " at " << hit.distance;
      EXPECT_NEAR(hit.outward.norm(), 1.0, 1e-12);
      EXPECT_NEAR((p - hit.closest).norm(), exact, 1e-9);
      ++near;
      inside += in;
    } else if (exact > band + 1e-9) {
      EXPECT_FALSE(found) << "point " << k << " at " << exact;
    }
  }
  EXPECT_GT(near, 150);
  EXPECT_GT(inside, 25);
}
