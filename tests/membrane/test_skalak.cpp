#include <gtest/gtest.h>

#include <cmath>

#include "bendlab/elasticity/elastic_law.hpp"
#include "bendlab/elasticity/skalak.hpp"
#include "bendlab/mesh/generators.hpp"
#include "membrane/deformations.hpp"

using namespace bendlab;

namespace {

using test::deform;
using test::rotation;

}  // namespace

TEST(Skalak, ZeroEnergyAndForceOnReference) {
  const TriMesh m = sphere_mesh(MeshFamily::MT1, 2);
  for (double C : {-0.4, 1.0, 10.0}) {
    const Skalak sk(m.topology_ptr(), m.positions(), 3.0, C);
    Points F(m.num_vertices(), 3);
    EXPECT_NEAR(sk.energy_and_forces(m.positions(), F), 0.0, 1e-13) << "C " << C;
    EXPECT_LT(F.cwiseAbs().maxCoeff(), 1e-12) << "C " << C;
    // Translated and rotated: still stress-free.
    Points y = m.positions() * rotation(0.7, 0.2, -1.3).transpose();
    y.rowwise() += Eigen::RowVector3d(2.0, -1.0, 0.5);
    EXPECT_NEAR(sk.energy_and_forces(y, F), 0.0, 1e-12) << "C " << C;
    EXPECT_LT(F.cwiseAbs().maxCoeff(), 1e-11) << "C " << C;
  }
}

TEST(Skalak, ForceIsMinusFiniteDifferenceGradient) {
  const TriMesh m = sphere_mesh(MeshFamily::MT1, 1);
  for (double C : {-0.3, 1.0, 7.0}) {
    const Skalak sk(m.topology_ptr(), m.positions(), 2.5, C);
    Points x = deform(m.positions());
    Points F(m.num_vertices(), 3);
    const double e = sk.energy_and_forces(x, F);
    EXPECT_NEAR(e, sk.energy(x), 1e-13 * e);
    const double h = 1e-6;
    double max_err = 0;
    for (int i = 0; i < x.rows(); ++i)
      for (int k = 0; k < 3; ++k) {
        const double x0 = x(i, k);
        x(i, k) = x0 + h;
        const double ep = sk.energy(x);
        x(i, k) = x0 - h;
        const double em = sk.energy(x);
        x(i, k) = x0;
        max_err = std::max(max_err, std::abs(F(i, k) + (ep - em) / (2 * h)));
      }
    EXPECT_LT(max_err, 1e-6 * F.cwiseAbs().maxCoeff()) << "C " << C;
  }
}

TEST(Skalak, InvariantUnderRigidMotionWithoutNetForceOrTorque) {
  const TriMesh m = sphere_mesh(MeshFamily::MT1, 2);
  const Skalak sk(m.topology_ptr(), m.positions(), 1.0, 2.0);
  const Points x = deform(m.positions());
  const Mat3 R = rotation(0.3, -1.1, 2.0);
  Points y = x * R.transpose();
  y.rowwise() += Eigen::RowVector3d(0.4, -2.0, 7.0);
  Points Fx, Fy;
  const double e = sk.energy_and_forces(x, Fx);
  EXPECT_GT(e, 0.0);
  EXPECT_NEAR(sk.energy_and_forces(y, Fy), e, 1e-12 * e);
  // Forces rotate with the shape.
  EXPECT_LT((Fy - Fx * R.transpose()).cwiseAbs().maxCoeff(), 1e-11 * Fx.cwiseAbs().maxCoeff());
  Vec3 sum = Vec3::Zero(), torque = Vec3::Zero();
  for (int i = 0; i < y.rows(); ++i) {
    sum += row(Fy, i);
    torque += row(y, i).cross(row(Fy, i));
  }
  const double scale = Fy.rowwise().norm().sum();
  EXPECT_LT(sum.norm(), 1e-13 * scale);
  EXPECT_LT(torque.norm(), 1e-13 * scale * y.rowwise().norm().maxCoeff());
}

TEST(Skalak, IsotropicDilationGivesTheAreaModulus) {
  // x -> (1 + s) x: l1 = l2 = 1 + s on every triangle, so with L = (1 + s)^2
  //   W = Gs/4 ((2L - 2)^2 + 2 (2L - 2) - 2 (L^2 - 1)) + C Gs/4 (L^2 - 1)^2   exactly,
  // and for small s W = 2 K s^2 + O(s^3) with the area modulus K = Gs (1 + 2C).
  const TriMesh m = sphere_mesh(MeshFamily::MT1, 2);
  double A0 = 0;
  for (int f = 0; f < m.num_faces(); ++f) {
    const Vec3 a = m.position(m.faces()(f, 0)), b = m.position(m.faces()(f, 1)), c = m.position(m.faces()(f, 2));
    A0 += 0.5 * (b - a).cross(c - a).norm();
  }
  const double kS = 3.0, Gs = kS / 3;
  for (double C : {-0.25, 0.0, 1.0, 10.0}) {
    const Skalak sk(m.topology_ptr(), m.positions(), kS, C);
    for (double s : {0.3, 1e-4}) {
      const double L = (1 + s) * (1 + s);
      const double W = Gs / 4 * ((2 * L - 2) * (2 * L - 2) + 2 * (2 * L - 2) - 2 * (L * L - 1)) +
                       C * Gs / 4 * (L * L - 1) * (L * L - 1);
      const double e = sk.energy(m.positions() * (1 + s));
      // At s = 1e-4 both sides lose digits to the cancellation in 2 I1 - 2 I2 = O(s^2).
      EXPECT_NEAR(e, W * A0, (s > 0.1 ? 1e-11 : 1e-6) * W * A0) << "C " << C << " s " << s;
      if (s < 1e-3) {
        EXPECT_NEAR(e, 2 * Gs * (1 + 2 * C) * s * s * A0, 5 * s * e) << "C " << C;
      }
    }
  }
}

TEST(Skalak, SmallStrainIsLinearElasticityWithPoissonRatioCOverOnePlusC) {
  // x -> x + s B x with symmetric B: on a face with orthonormal in-plane frame (t1, t2) the
  // small strain is e_ab = s t_a . B t_b. Linear isotropic membrane elasticity with shear modulus
  // Gs and Poisson ratio nu (Young modulus Es = 2 Gs (1 + nu)) stores
  //   W = Es / (2 (1 - nu^2)) (tr e^2 - 2 (1 - nu) det e) = Gs / (1 - nu) tr e^2 - 2 Gs det e,
  // which is Skalak's W to O(s^3) exactly when nu = C / (1 + C) (Barthes-Biesel 2002).
  const TriMesh m = sphere_mesh(MeshFamily::MT1, 2);
  Mat3 B;
  B << 1.0, 0.3, -0.2,  //
      0.3, -0.7, 0.5,   //
      -0.2, 0.5, 0.4;
  const double kS = 1.5, Gs = kS / 3, s = 1e-5;
  for (double C : {-0.3, 0.0, 1.0, 5.0}) {
    const double nu = C / (1 + C);
    const Skalak sk(m.topology_ptr(), m.positions(), kS, C);
    EXPECT_DOUBLE_EQ(sk.poisson_ratio(), nu);
    double linear = 0;
    for (int f = 0; f < m.num_faces(); ++f) {
      const Vec3 a = m.position(m.faces()(f, 0)), b = m.position(m.faces()(f, 1)), c = m.position(m.faces()(f, 2));
      const Vec3 n2 = (b - a).cross(c - a);
      const Vec3 t1 = (b - a).normalized(), t2 = n2.normalized().cross(t1);
      const double e11 = s * t1.dot(B * t1), e22 = s * t2.dot(B * t2), e12 = s * t1.dot(B * t2);
      const double tr = e11 + e22, det = e11 * e22 - e12 * e12;
      linear += 0.5 * n2.norm() * (Gs / (1 - nu) * tr * tr - 2 * Gs * det);
    }
    const Points y = m.positions() + s * m.positions() * B.transpose();
    EXPECT_NEAR(sk.energy(y), linear, 1e-3 * linear) << "C " << C;
  }
}

TEST(Skalak, FactoryAndBadInput) {
  const TriMesh m = sphere_mesh(MeshFamily::MT1, 0);
  const auto law = make_elastic_law("skalak", m.topology_ptr(), m.positions(), 2.0, 4.0);
  EXPECT_EQ(law->name(), "Skalak");
  EXPECT_EQ(dynamic_cast<const Skalak&>(*law).C(), 4.0);
  EXPECT_EQ(law->kS(), 2.0);
  EXPECT_THROW(Skalak(m.topology_ptr(), m.positions(), 0.0, 1.0), Error);
  EXPECT_THROW(Skalak(m.topology_ptr(), m.positions(), 1.0, -0.5), Error);
  EXPECT_THROW(Skalak(m.topology_ptr(), m.positions(), 1.0, std::nan("")), Error);
  Points flat = m.positions();
  flat.setZero();
  EXPECT_THROW(Skalak(m.topology_ptr(), flat, 1.0, 1.0), Error);
}
