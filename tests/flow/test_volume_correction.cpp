#include <gtest/gtest.h>

#include <cmath>

#include "bendlab/flow/volume_correction.hpp"
#include "bendlab/geometry/measures.hpp"
#include "bendlab/mesh/generators.hpp"

using namespace bendlab;

namespace {
Points bumpy(const Points& x) {
  Points y = x;
  for (int i = 0; i < x.rows(); ++i) {
    const double s = 1 + 0.2 * x(i, 0) * x(i, 1) + 0.1 * std::cos(3 * x(i, 2));
    y.row(i) *= s;
    y(i, 0) *= 1.3;
  }
  return y;
}
}  // namespace

TEST(VolumeCorrection, GradientMatchesFiniteDifferences) {
  const TriMesh m = sphere_mesh(MeshFamily::MT1, 1);
  Points x = bumpy(m.positions());
  Points a;
  volume_gradient(m.topology(), x, a);
  // V is cubic in each coordinate; the central difference error is h^2/6 V''' with |V'''| = O(1).
  const double h = 1e-5;
  double max_err = 0;
  for (int i = 0; i < x.rows(); ++i)
    for (int k = 0; k < 3; ++k) {
      const double x0 = x(i, k);
      x(i, k) = x0 + h;
      const double vp = enclosed_volume(m.topology(), x);
      x(i, k) = x0 - h;
      const double vm = enclosed_volume(m.topology(), x);
      x(i, k) = x0;
      max_err = std::max(max_err, std::abs(a(i, k) - (vp - vm) / (2 * h)));
    }
  EXPECT_LT(max_err, 1e-9);
  // Euler: sum_i a_i . x_i = 3 V (V is homogeneous of degree 3).
  EXPECT_NEAR(a.cwiseProduct(x).sum(), 3 * enclosed_volume(m.topology(), x), 1e-12);
}

TEST(VolumeCorrection, ProjectionRemovesFluxAndIsIdempotent) {
  const TriMesh m = sphere_mesh(MeshFamily::MT1, 2);
  const Points x = bumpy(m.positions());
  Points a;
  volume_gradient(m.topology(), x, a);
  Points u = x;  // a dilation: large positive flux
  u.col(2) += x.col(0).array().square().matrix();
  const double q0 = project_zero_flux(a, u);
  EXPECT_GT(q0, 0.1);
  const double scale = u.cwiseAbs().maxCoeff() * a.cwiseAbs().sum();
  EXPECT_LT(std::abs(discrete_flux(a, u)), 1e-14 * scale);
  const Points u1 = u;
  const double q1 = project_zero_flux(a, u);
  EXPECT_LT(std::abs(q1), 1e-14 * scale);
  EXPECT_LT((u - u1).cwiseAbs().maxCoeff(), 1e-15 * u1.cwiseAbs().maxCoeff() + 1e-300);
}

TEST(VolumeCorrection, RescaleRestoresVolumeAboutCentroid) {
  const TriMesh m = sphere_mesh(MeshFamily::MT1, 2);
  Points x = bumpy(m.positions());
  x.rowwise() += Eigen::RowVector3d(0.5, -1, 2);
  const Vec3 c0 = volume_centroid(m.topology(), x);
  const double v = enclosed_volume(m.topology(), x);
  const double s = rescale_to_volume(m.topology(), x, 1.1 * v);
  EXPECT_NEAR(s, std::cbrt(1.1), 1e-15);
  EXPECT_NEAR(enclosed_volume(m.topology(), x), 1.1 * v, 1e-13 * v);
  EXPECT_LT((volume_centroid(m.topology(), x) - c0).norm(), 1e-13);
}
