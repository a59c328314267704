#include <gtest/gtest.h>

#include <cmath>

#include "bendlab/elasticity/neo_hookean.hpp"
#include "bendlab/mesh/generators.hpp"
#include "membrane/deformations.hpp"

using namespace bendlab;

namespace {

using test::deform;
using test::rotation;

}  // namespace

TEST(NeoHookean, ZeroEnergyAndForceOnReference) {
  const TriMesh m = sphere_mesh(MeshFamily::MT1, 2);
  const NeoHookean nh(m.topology_ptr(), m.positions(), 3.0);
  Points F(m.num_vertices(), 3);
  const double e = nh.energy_and_forces(m.positions(), F);
  // I1 = 0, I2 = 0 on the reference: eps_S = kS/6 (0 + 1 - 1) = 0, and it is the minimum.
  EXPECT_NEAR(e, 0.0, 1e-13);
  EXPECT_LT(F.cwiseAbs().maxCoeff(), 1e-12);
}

TEST(NeoHookean, ForceIsMinusFiniteDifferenceGradient) {
  const TriMesh m = sphere_mesh(MeshFamily::MT1, 1);
  const NeoHookean nh(m.topology_ptr(), m.positions(), 2.5);
  Points x = deform(m.positions());
  Points F(m.num_vertices(), 3);
  nh.forces(x, F);
  const double h = 1e-6;
  double max_err = 0;
  for (int i = 0; i < x.rows(); ++i)
    for (int k = 0; k < 3; ++k) {
      const double x0 = x(i, k);
      x(i, k) = x0 + h;
      const double ep = nh.energy(x);
      x(i, k) = x0 - h;
      const double em = nh.energy(x);
      x(i, k) = x0;
      max_err = std::max(max_err, std::abs(F(i, k) + (ep - em) / (2 * h)));
    }
  EXPECT_LT(max_err, 1e-6 * F.cwiseAbs().maxCoeff());
}

TEST(NeoHookean, EnergyInvariantUnderRigidMotion) {
  const TriMesh m = sphere_mesh(MeshFamily::MT1, 2);
  const NeoHookean nh(m.topology_ptr(), m.positions(), 1.0);
  const Points x = deform(m.positions());
  const Mat3 R = rotation(0.3, -1.1, 2.0);
  Points y = x * R.transpose();
  y.rowwise() += Eigen::RowVector3d(0.4, -2.0, 7.0);
  const double e = nh.energy(x);
  EXPECT_GT(e, 0.0);
  EXPECT_NEAR(nh.energy(y), e, 1e-12 * e);
}

TEST(NeoHookean, ForcesSumToZeroWithoutTorque) {
  const TriMesh m = sphere_mesh(MeshFamily::MT1, 2);
  const NeoHookean nh(m.topology_ptr(), m.positions(), 1.0);
  Points x = deform(m.positions());
  x.rowwise() += Eigen::RowVector3d(1.0, 2.0, -3.0);  // torque about the origin, away from the body
  Points F(m.num_vertices(), 3);
  nh.forces(x, F);
  Vec3 sum = Vec3::Zero(), torque = Vec3::Zero();
  for (int i = 0; i < x.rows(); ++i) {
    sum += row(F, i);
    torque += row(x, i).cross(row(F, i));
  }
  const double scale = F.rowwise().norm().sum();
  EXPECT_LT(sum.norm(), 1e-13 * scale);
  EXPECT_LT(torque.norm(), 1e-13 * scale * x.rowwise().norm().maxCoeff());
}

TEST(NeoHookean, UniaxialStretchMatchesAnalyticEnergy) {
  // x -> x + s x e_x maps a flat triangle with unit normal n affinely; in its plane
  // C = P + (2 s + s^2) t t^T with t = P e_x, so l1^2 = 1 + (2 s + s^2)(1 - n_x^2), l2 = 1 and
  // eps_S = kS/6 (l1^2 + 1/l1^2 - 2) exactly.
  // For small s the continuum limit is eps_S = 2 kS/3 (e1^2 + e2^2 + e1 e2) with e1 = s (1 - n_x^2),
  // e2 = 0, and over the unit sphere int (1 - n_x^2)^2 dS = 32 pi / 15: E_S = 64 pi kS s^2 / 45.
  const double kS = 3.0, s = 1e-3;
  for (int level : {2, 3}) {
    const TriMesh m = sphere_mesh(MeshFamily::MT1, level);
    const NeoHookean nh(m.topology_ptr(), m.positions(), kS);
    Points y = m.positions();
    y.col(0) *= 1 + s;
    double exact = 0;
    const Faces& F = m.faces();
    for (int f = 0; f < m.num_faces(); ++f) {
      const Vec3 a = m.position(F(f, 0)), b = m.position(F(f, 1)), c = m.position(F(f, 2));
      const Vec3 n2 = (b - a).cross(c - a);
      const double area = 0.5 * n2.norm(), nx = n2.x() / n2.norm();
      const double l2 = 1 + (2 * s + s * s) * (1 - nx * nx);
      exact += area * kS / 6 * (l2 + 1 / l2 - 2);
    }
    EXPECT_NEAR(nh.energy(y), exact, 1e-9 * exact) << "level " << level;
    const double continuum = 64 * M_PI * kS * s * s / 45;
    // Flat triangles under-estimate the sphere's area by O(h^2): 2% at 1280 triangles.
    EXPECT_NEAR(nh.energy(y), continuum, (level == 2 ? 0.06 : 0.02) * continuum) << "level " << level;
  }
}

TEST(NeoHookean, RejectsBadInput) {
  const TriMesh m = sphere_mesh(MeshFamily::MT1, 0);
  EXPECT_THROW(NeoHookean(m.topology_ptr(), m.positions(), 0.0), Error);
  Points flat = m.positions();
  flat.setZero();
  EXPECT_THROW(NeoHookean(m.topology_ptr(), flat, 1.0), Error);
}
