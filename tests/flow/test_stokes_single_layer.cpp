#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "bendlab/bending/bending_method.hpp"
#include "bendlab/flow/bim/stokes_single_layer.hpp"
#include "bendlab/geometry/measures.hpp"
#include "bendlab/mesh/generators.hpp"
#include "bendlab/surfaces/analytic_surface.hpp"
#include "flow/single_layer_test_support.hpp"

using namespace bendlab;
using namespace bendlab::test_support;

namespace {
struct Errors {
  double h, uniform, normal;
};

Errors sphere_errors(int level) {
  const TriMesh m = sphere_mesh(MeshFamily::MT1, level);
  const int n = m.num_vertices();
  const StokesSingleLayer sl(m.topology_ptr());
  const double mu = 2.0;
  const Vec3 f0(0.3, -1.0, 0.5);
  Points f(n, 3), u;
  f.rowwise() = f0.transpose();
  sl.velocity(m.positions(), f, mu, u);
  // A rigid sphere (R = 1) under uniform traction f0 translates with u = 2 R f0 / (3 mu).
  const Vec3 exact = 2.0 * f0 / (3.0 * mu);
  double eu = 0;
  for (int i = 0; i < n; ++i) eu = std::max(eu, (row(u, i) - exact).norm() / exact.norm());
  // A uniform pressure p n exerts no net flow: u = 0. Scale by the rigid velocity of |f| = p.
  const double p = 1.7;
  for (int i = 0; i < n; ++i) f.row(i) = p * m.positions().row(i) / m.positions().row(i).norm();
  sl.velocity(m.positions(), f, mu, u);
  const double en = u.rowwise().norm().maxCoeff() / (2.0 * p / (3.0 * mu));
  return {mean_edge_length(m.topology(), m.positions()), eu, en};
}
}  // namespace

TEST(StokesSingleLayer, UniformAndNormalDensityOnSphereConverge) {
  std::vector<Errors> e;
  for (int level = 1; level <= 3; ++level) e.push_back(sphere_errors(level));
  for (std::size_t k = 0; k < e.size(); ++k)
    RecordProperty("level" + std::to_string(k + 1), std::to_string(e[k].uniform) + " " + std::to_string(e[k].normal));
  // Flat triangles miss the sphere by O(h^2) and the quadrature is of higher order: the errors
  // fall like h^2 (observed order between 1.7 and 2.3 per refinement).
  for (std::size_t k = 1; k < e.size(); ++k) {
    const double hl = std::log(e[k - 1].h / e[k].h);
    const double ou = std::log(e[k - 1].uniform / e[k].uniform) / hl;
    const double on = std::log(e[k - 1].normal / e[k].normal) / hl;
    EXPECT_GT(ou, 1.7) << "uniform, level " << k + 1;
    EXPECT_GT(on, 1.7) << "normal, level " << k + 1;
  }
  EXPECT_LT(e.back().uniform, 5e-3);
  EXPECT_LT(e.back().normal, 5e-3);
}

TEST(StokesSingleLayer, LinearInDensityAndInverseInViscosity) {
  const TriMesh m = sphere_mesh(MeshFamily::MT1, 1);
  const StokesSingleLayer sl(m.topology_ptr());
  Points f1 = m.positions().array().sin().matrix(), f2 = m.positions().array().square().matrix();
  Points u1, u2, u12;
  sl.velocity(m.positions(), f1, 1.0, u1);
  sl.velocity(m.positions(), f2, 1.0, u2);
  const Points f12 = 2.0 * f1 - 3.0 * f2;
  sl.velocity(m.positions(), f12, 4.0, u12);
  EXPECT_LT((u12 - (2.0 * u1 - 3.0 * u2) / 4.0).cwiseAbs().maxCoeff(), 1e-14 * u1.cwiseAbs().maxCoeff() * 10);
}

TEST(StokesSingleLayer, RotationEquivariant) {
  // Rotating the mesh and the density rotates the velocity (regular and polar parts alike), to
  // rounding with the reference quadrature.
  const TriMesh m = sphere_mesh(MeshFamily::MT1, 2);
  SingleLayerOptions o;
  o.quadrature = SingleLayerQuadrature::all7;
  const StokesSingleLayer sl(m.topology_ptr(), o);
  Points f(m.num_vertices(), 3);
  for (int i = 0; i < f.rows(); ++i) f.row(i) << m.positions()(i, 1), std::cos(m.positions()(i, 0)), 0.4;
  Points u, ur;
  sl.velocity(m.positions(), f, 1.0, u);
  const Mat3 R = Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  const Points xr = m.positions() * R.transpose(), fr = f * R.transpose();
  sl.velocity(xr, fr, 1.0, ur);
  EXPECT_LT((ur - u * R.transpose()).cwiseAbs().maxCoeff(), 1e-13);
}

TEST(StokesSingleLayer, QuadratureNamesAndOptions) {
  EXPECT_EQ(single_layer_quadrature("all7"), SingleLayerQuadrature::all7);
  EXPECT_EQ(single_layer_quadrature("adaptive"), SingleLayerQuadrature::adaptive);
  EXPECT_EQ(to_string(SingleLayerQuadrature::all7), "all7");
  EXPECT_EQ(to_string(SingleLayerQuadrature::adaptive), "adaptive");
  EXPECT_THROW(single_layer_quadrature("fast"), Error);
  const TriMesh m = sphere_mesh(MeshFamily::MT1, 0);
  SingleLayerOptions o;
  o.far_ratio = 1.0;  // a cluster at a target's own triangles could be taken as far
  EXPECT_THROW(StokesSingleLayer(m.topology_ptr(), o), Error);
  o = {};
  o.cluster_size = 0;
  EXPECT_THROW(StokesSingleLayer(m.topology_ptr(), o), Error);
  o = {};
  o.far_order = 5;
  EXPECT_THROW(StokesSingleLayer(m.topology_ptr(), o), Error);
}

TEST(StokesSingleLayer, DefaultIsTheReferenceRule) {
  EXPECT_EQ(SingleLayerOptions{}.quadrature, SingleLayerQuadrature::all7);
}

