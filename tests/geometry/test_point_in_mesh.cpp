// The winding number of closed meshes (point_in_mesh.hpp): 1 inside, 0 outside, exact for any
// closed outward-oriented mesh, on a sphere and on a non-convex (dented) shape.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "bendlab/geometry/point_in_mesh.hpp"
#include "bendlab/mesh/generators.hpp"

using namespace bendlab;

TEST(PointInMesh, WindingNumberIsOneInsideAndZeroOutsideASphere) {
  const TriMesh m = sphere_mesh(MeshFamily::MT1, 2);
  const Points& x = m.positions();
  const BoundingBox box = bounding_box(x);
  EXPECT_NEAR(winding_number(m.topology(), x, Vec3(0.1, -0.2, 0.3)), 1.0, 1e-12);
  EXPECT_NEAR(winding_number(m.topology(), x, Vec3(1.5, 0.0, 0.0)), 0.0, 1e-12);
  EXPECT_NEAR(winding_number(m.topology(), x, Vec3(0.0, 0.0, -7.0)), 0.0, 1e-12);
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-1.3, 1.3);
  int checked = 0;
  for (int n = 0; n < 300; ++n) {
    const Vec3 p(u(rng), u(rng), u(rng));
    // The inscribed sphere of the 320-triangle mesh has radius above 0.95; points between it and
    // the circumscribed unit sphere are left out.
    if (p.norm() > 0.94 && p.norm() < 1.0) continue;
    EXPECT_EQ(contains(m.topology(), x, box, p), p.norm() < 0.94) << p.transpose();
    ++checked;
  }
  EXPECT_GT(checked, 250);
}

TEST(PointInMesh, HandlesANonConvexShape) {
  // The sphere with a deep dent pushed in along +z: the point just above the dent's bottom (inside
  // the sphere's ball but outside the dented shape) is outside; one below it is inside.
  const TriMesh s = sphere_mesh(MeshFamily::MT1, 3);
  Points x = s.positions();
  for (Eigen::Index i = 0; i < x.rows(); ++i) {
    const double z = x(i, 2);
    if (z > 0.5) x(i, 2) = 0.5 - 1.6 * (z - 0.5);  // the cap above z = 0.5 folded down
  }
  const TriMesh dented(s.topology_ptr(), x);
  const BoundingBox box = bounding_box(x);
  EXPECT_FALSE(contains(dented.topology(), x, box, Vec3(0, 0, 0.2)));
  EXPECT_NEAR(winding_number(dented.topology(), x, Vec3(0, 0, 0.2)), 0.0, 1e-10);
  EXPECT_TRUE(contains(dented.topology(), x, box, Vec3(0, 0, -0.5)));
  EXPECT_TRUE(contains(dented.topology(), x, box, Vec3(0.7, 0, 0.0)));
  EXPECT_FALSE(contains(dented.topology(), x, box, Vec3(0.7, 0, 0.3)));  // above the dent at that radius (z = 0.16)
}
