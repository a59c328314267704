// The reference form of Belkin's heat-kernel operator (bending/belkin_reference.cpp, neighbours =
// all): every vertex against every point, which the grid form is tested against.
#include <gtest/gtest.h>

#include <cmath>

#include "bendlab/bending/belkin.hpp"
#include "bendlab/geometry/measures.hpp"
#include "bendlab/mesh/generators.hpp"
#include "bendlab/surfaces/analytic_surface.hpp"

using namespace bendlab;

namespace {

BelkinOptions reference(bool half_space = true) {
  BelkinOptions o;
  o.neighbours = BelkinOptions::Neighbours::all;
  o.half_space = half_space;
  return o;
}

// Eq. (13) summed vertex by vertex and point by point with std::exp, no cut-off, the half-space
// rule with the implementation's margin: what the reference must be up to the order of its sums.
Points all_pairs(const Topology& t, const Points& x, const Points& w, bool half_space) {
  const MeshGeometry g = MeshGeometry::compute(t, x);
  const Vec3 c = volume_centroid(t, x);
  Scalars lumped = Scalars::Zero(t.num_vertices());
  for (int f = 0; f < t.num_faces(); ++f)
    for (int k = 0; k < 3; ++k) lumped[t.faces()(f, k)] += g.face_area[f] / 3;
  Points out(t.num_vertices(), 3);
  for (int i = 0; i < t.num_vertices(); ++i) {
    const Vec3 xi = row(x, i);
    const double a = g.mixed_area[i];
    Eigen::RowVector3d s = Eigen::RowVector3d::Zero();
    for (int p = 0; p < t.num_vertices(); ++p) {
      const Vec3 xp = row(x, p);
      if (half_space && (xp - c).dot(xi - c) <= 1e-9 * (xp - c).norm() * (xi - c).norm()) continue;
      s += lumped[p] * std::exp(-(xp - xi).squaredNorm() / (4 * a)) * (w.row(p) - w.row(i));
    }
    out.row(i) = s / (4 * M_PI * a * a);
  }
  return out;
}

}  // namespace

TEST(BelkinReference, IsTheAllPairsSumOfEq13) {
  const TriMesh m = sphere_mesh(MeshFamily::MT1, 2);
  const Points x = make_rbc()->map_from_unit_sphere(m.positions());
  const MeshGeometry g = MeshGeometry::compute(m.topology(), x);
  Points w(m.num_vertices(), 3);
  for (int i = 0; i < w.rows(); ++i) w.row(i) = Eigen::RowVector3d(std::sin(3 * x(i, 0)), x(i, 2) * x(i, 1), x(i, 0));
  for (const bool half_space : {true, false}) {
    const BelkinLaplacian lap(m.topology(), x, g, reference(half_space));
    const Points got = lap.apply(w), expect = all_pairs(m.topology(), x, w, half_space);
    EXPECT_LE((got - expect).cwiseAbs().maxCoeff(), 1e-12 * expect.cwiseAbs().maxCoeff()) << half_space;
    // Lap x from the positions it was built from: the same as applying it to x (to rounding).
    const Points lx = lap.apply_to_positions(), ex = all_pairs(m.topology(), x, x, half_space);
    EXPECT_LE((lx - ex).cwiseAbs().maxCoeff(), 1e-12 * ex.cwiseAbs().maxCoeff()) << half_space;
  }
}

TEST(BelkinReference, ConstantGivesExactlyZeroAndIntoFormsAgree) {
  const TriMesh m = sphere_mesh(MeshFamily::MT2, 2);
  const Points x = make_rbc()->map_from_unit_sphere(m.positions());
  const MeshGeometry g = MeshGeometry::compute(m.topology(), x);
  BelkinLaplacian lap(m.topology(), x, g, reference());
  const Scalars c = Scalars::Constant(m.num_vertices(), 3.25);
  EXPECT_EQ(lap.apply(c).cwiseAbs().maxCoeff(), 0.0);
  // The *_into forms (the operator's own buffers) give apply()'s numbers.
  Scalars w = x.col(0).array().sin().matrix(), out;
  Points px;
  lap.apply_into(w, out);
  EXPECT_EQ(out, lap.apply(w));
  lap.apply_into(x, px);
  EXPECT_EQ(px, lap.apply(x));
  lap.apply_to_positions_into(px);
  EXPECT_EQ(px, lap.apply_to_positions());
}
