#include <gtest/gtest.h>

#include <cmath>

#include "bendlab/capsule/capsule_shape.hpp"
#include "bendlab/mesh/generators.hpp"

using namespace bendlab;

namespace {
Points ellipsoid(const Points& sphere, double a, double b, double c, double phi, const Vec3& shift = Vec3::Zero()) {
  // Scale by (a, b, c), then rotate by phi about -e_y, which turns e_x towards e_z in the x-z plane.
  const Mat3 R = Eigen::AngleAxisd(-phi, Vec3::UnitY()).toRotationMatrix();
  Points x = sphere;
  x.col(0) *= a;
  x.col(1) *= b;
  x.col(2) *= c;
  x = (x * R.transpose()).eval();
  x.rowwise() += shift.transpose();
  return x;
}
}  // namespace

TEST(CapsuleShape, SphereIsUndeformed) {
  const TriMesh m = sphere_mesh(MeshFamily::MT1, 3);
  const CapsuleShape s = capsule_shape(m.topology(), m.positions());
  // The MT1 meshes keep the icosahedron's symmetry, under which every symmetric rank-2 tensor is
  // isotropic: the second moment is a multiple of the identity, so D = 0 up to round-off.
  EXPECT_LT(s.D, 1e-12);
  EXPECT_NEAR(s.a, 1.0, 0.01);
}

TEST(CapsuleShape, EllipsoidHalfAxesConvergeAndDIsExact) {
  const double a = 1.4, b = 1.0, c = 0.7;
  double prev = 1e9;
  for (int level = 1; level <= 4; ++level) {
    const TriMesh m = sphere_mesh(MeshFamily::MT1, level);
    const CapsuleShape s = capsule_shape(m.topology(), ellipsoid(m.positions(), a, b, c, 0.0, Vec3(0.3, 0.1, -0.2)));
    // The mesh's isotropic second moment (see above) maps to m abc diag(a^2, b^2, c^2): the
    // equivalent half axes are (a, b, c) times one common factor, and D is exact at any resolution.
    EXPECT_NEAR(s.D, (a - c) / (a + c), 1e-12) << "level " << level;
    EXPECT_NEAR(s.a / s.c, a / c, 1e-12);
    EXPECT_NEAR(s.b / s.c, b / c, 1e-12);
    // The common factor tends to one with the flat-triangle error O(h^2): a quarter per level.
    const double err = std::abs(s.a - a) / a;
    EXPECT_LT(err, 0.3 * prev) << "level " << level;
    prev = err;
  }
  EXPECT_LT(prev, 2e-3);
}

TEST(CapsuleShape, InclinationOfRotatedEllipsoid) {
  const TriMesh m = sphere_mesh(MeshFamily::MT1, 2);
  for (double phi : {0.0, 0.3, M_PI / 4, 1.2, -0.5, -1.4}) {
    const CapsuleShape s = capsule_shape(m.topology(), ellipsoid(m.positions(), 1.5, 1.0, 0.8, phi));
    EXPECT_NEAR(s.theta, phi, 1e-12) << "phi " << phi;
    EXPECT_NEAR(s.D, 0.7 / 2.3, 1e-12);
    EXPECT_NEAR(std::abs(s.long_axis.y()), 0.0, 1e-12);
  }
  // pi/2 and -pi/2 are the same axis; the range is (-pi/2, pi/2].
  const CapsuleShape s = capsule_shape(m.topology(), ellipsoid(m.positions(), 1.5, 1.0, 0.8, -M_PI / 2));
  EXPECT_NEAR(s.theta, M_PI / 2, 1e-12);
}

TEST(CapsuleShape, InertiaOfEllipsoid) {
  const TriMesh m = sphere_mesh(MeshFamily::MT1, 2);
  const CapsuleShape s = capsule_shape(m.topology(), ellipsoid(m.positions(), 1.3, 1.1, 0.9, 0.0));
  // I = V/5 diag(b^2 + c^2, a^2 + c^2, a^2 + b^2) with the equivalent half axes.
  const double k = s.volume / 5;
  EXPECT_NEAR(s.inertia(0, 0), k * (s.b * s.b + s.c * s.c), 1e-13);
  EXPECT_NEAR(s.inertia(1, 1), k * (s.a * s.a + s.c * s.c), 1e-13);
  EXPECT_NEAR(s.inertia(2, 2), k * (s.a * s.a + s.b * s.b), 1e-13);
  EXPECT_NEAR(s.inertia(0, 2), 0.0, 1e-13);
}
