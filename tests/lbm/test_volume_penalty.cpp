#include <gtest/gtest.h>

#include "bendlab/flow/lbm/volume_penalty.hpp"
#include "bendlab/mesh/generators.hpp"

using namespace bendlab;
using namespace bendlab::lbm;

TEST(VolumePenalty, ForceIsMinusTheGradientOfItsEnergy) {
  const TriMesh m = sphere_mesh(MeshFamily::MT1, 2);
  Points x = m.positions();
  x.col(0) *= 1.3;  // an ellipsoid, slightly off-centre
  x.col(2) *= 0.8;
  x.rowwise() += Vec3(0.1, -0.2, 0.3).transpose();
  const Faces& f = m.faces();
  const double kV = 2.5, V0 = 1.15 * enclosed_volume(f, x);
  Points F;
  add_volume_penalty(f, x, kV, V0, F);
  const double h = 1e-6;
  double worst = 0, scale = 0;
  for (int i = 0; i < x.rows(); ++i) {
    for (int d = 0; d < 3; ++d) {
      Points xp = x, xm = x, dummy;
      xp(i, d) += h;
      xm(i, d) -= h;
      const double g = (add_volume_penalty(f, xp, kV, V0, dummy) - add_volume_penalty(f, xm, kV, V0, dummy)) / (2 * h);
      worst = std::max(worst, std::abs(F(i, d) + g));
      scale = std::max(scale, std::abs(g));
    }
  }
  EXPECT_LT(worst, 1e-7 * scale);
  // Translation invariance: the forces sum to zero.
  EXPECT_LT(F.colwise().sum().norm(), 1e-12 * scale);
}

TEST(VolumePenalty, VanishesAtTheReferenceVolumeAndMatchesEspressoScaling) {
  const TriMesh m = sphere_mesh(MeshFamily::MT1, 2);
  const Faces& f = m.faces();
  const double V = enclosed_volume(f, m.positions());
  Points F;
  EXPECT_EQ(add_volume_penalty(f, m.positions(), 3.0, V, F), 0.0);
  EXPECT_LT(F.norm(), 1e-14);
  // Each triangle adds -kV (V - V0)/V A_t n_t to each vertex: a radial pull on a sphere larger
  // than its reference, summing to 3 kV (V - V0)/V |sum_t A_t n_t ... | per vertex; check the sign.
  Points G;
  add_volume_penalty(f, m.positions(), 3.0, 0.9 * V, G);
  for (int i = 0; i < G.rows(); ++i) EXPECT_LT(G.row(i).dot(m.positions().row(i)), 0.0);
  EXPECT_THROW(add_volume_penalty(f, m.positions(), 3.0, 0.0, G), Error);
}
