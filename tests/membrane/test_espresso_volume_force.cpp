#include <gtest/gtest.h>

#include <memory>

#include "bendlab/membrane/espresso_volume_force.hpp"
#include "bendlab/membrane/membrane_model.hpp"
#include "bendlab/mesh/enclosed_volume.hpp"
#include "bendlab/mesh/generators.hpp"

using namespace bendlab;

TEST(EspressoVolumeForce, ForceIsMinusTheGradientOfItsEnergy) {
  const TriMesh m = sphere_mesh(MeshFamily::MT1, 2);
  Points x = m.positions();
  x.col(0) *= 1.3;  // an ellipsoid, slightly off-centre
  x.col(2) *= 0.8;
  x.rowwise() += Vec3(0.1, -0.2, 0.3).transpose();
  const Topology& t = m.topology();
  const EspressoVolumeForce vf(2.5);
  const double V0 = 1.15 * enclosed_volume(t, x);
  Points F = Points::Zero(x.rows(), 3);
  vf.add_forces(t, x, V0, F);
  const double h = 1e-6;
  double worst = 0, scale = 0;
  for (int i = 0; i < x.rows(); ++i) {
    for (int d = 0; d < 3; ++d) {
      Points xp = x, xm = x;
      xp(i, d) += h;
      xm(i, d) -= h;
      const double g = (*vf.energy(t, xp, V0) - *vf.energy(t, xm, V0)) / (2 * h);
      worst = std::max(worst, std::abs(F(i, d) + g));
      scale = std::max(scale, std::abs(g));
    }
  }
  EXPECT_LT(worst, 1e-7 * scale);
  // Translation invariance: the forces sum to zero.
  EXPECT_LT(F.colwise().sum().norm(), 1e-12 * scale);
}

TEST(EspressoVolumeForce, VanishesAtTheReferenceVolumePullsInwardWhenInflated) {
  const TriMesh m = sphere_mesh(MeshFamily::MT1, 2);
  const Topology& t = m.topology();
  const double V = enclosed_volume(t, m.positions());
  const EspressoVolumeForce vf(3.0);
  Points F = Points::Zero(m.num_vertices(), 3);
  EXPECT_EQ(*vf.energy(t, m.positions(), V), 0.0);
  vf.add_forces(t, m.positions(), V, F);
  EXPECT_LT(F.norm(), 1e-14);
  Points G = Points::Zero(m.num_vertices(), 3);
  vf.add_forces(t, m.positions(), 0.9 * V, G);
  for (int i = 0; i < G.rows(); ++i) EXPECT_LT(G.row(i).dot(m.positions().row(i)), 0.0);
  EXPECT_THROW(vf.add_forces(t, m.positions(), 0.0, G), Error);
  EXPECT_THROW(EspressoVolumeForce(-1.0), Error);
  EXPECT_DOUBLE_EQ(EspressoVolumeForce::for_membrane(0.5).kappa_V(), 50.0);
}

TEST(EspressoVolumeForce, IsAddedByTheMembraneModel) {
  const TriMesh m = sphere_mesh(MeshFamily::MT1, 2);
  MembraneParameters p;
  p.kS = 2;
  auto vf = std::make_shared<const EspressoVolumeForce>(EspressoVolumeForce::for_membrane(p.kS));
  MembraneParameters q = p;
  q.volume_force = vf;
  const MembraneModel plain(m, p), with(m, q);
  Points x = m.positions() * 1.05;  // inflated: the volume force pulls every node inwards
  Points F0, F1, Fv = Points::Zero(x.rows(), 3);
  plain.forces(x, F0);
  with.forces(x, F1);
  vf->add_forces(m.topology(), x, with.reference_volume(), Fv);
  EXPECT_LT((F1 - F0 - Fv).norm(), 1e-12 * Fv.norm());
  EXPECT_GT(*with.volume_energy(x), 0.0);
}
