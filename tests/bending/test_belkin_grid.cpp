// The grid form of Belkin's heat-kernel operator (bending/belkin_grid.cpp): the cell list's
// truncated sum against the all-pairs reference, the kept kernel weights, and an operator
// prepared for one shape after another.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>

#include "bendlab/bending/belkin.hpp"
#include "bendlab/mesh/generators.hpp"
#include "bendlab/surfaces/analytic_surface.hpp"
#include "bending/shape_test_support.hpp"

using namespace bendlab;
using test_support::rbc_points;

namespace {
double rel_max_diff(const Eigen::MatrixXd& a, const Eigen::MatrixXd& ref) {
  return (a - ref).cwiseAbs().maxCoeff() / ref.cwiseAbs().maxCoeff();
}
// A smooth, non-symmetric deformation of the RBC (as a capsule in shear flow gets).
Points deformed(const Points& x) {
  Points y = x;
  for (int i = 0; i < x.rows(); ++i) {
    y(i, 0) += 0.3 * x(i, 2) + 0.05 * std::sin(3 * x(i, 1));
    y(i, 1) *= 0.8;
    y(i, 2) += 0.1 * x(i, 0) * x(i, 0);
  }
  return y;
}
}  // namespace

// The O(N) grid form (kernel weights below kernel_cutoff dropped) against the O(N^2) reference:
// equal to 1e-8 relative (max norm) with the default cutoff, on the RBC and a deformed RBC at 1280
// and 5120 triangles, for Lap of a scalar field and Method D's H (from Lap x) and force density.
TEST(BelkinLaplacian, GridFormEqualsAllPairsForm) {
  BelkinOptions all, grid;
  all.neighbours = BelkinOptions::Neighbours::all;
  for (int level : {3, 4}) {
    const TriMesh m = sphere_mesh(MeshFamily::MT1, level);
    for (bool deform : {false, true}) {
      const Points x = deform ? deformed(rbc_points(m)) : rbc_points(m);
      const MeshGeometry g = MeshGeometry::compute(m.topology(), x);
      Scalars w(m.num_vertices());
      for (int i = 0; i < w.size(); ++i) w[i] = std::sin(3 * x(i, 0)) + x(i, 2) * x(i, 1);
      const BelkinLaplacian la(m.topology(), x, g, all), lg(m.topology(), x, g, grid);
      const double dw = rel_max_diff(lg.apply(w), la.apply(w));
      // Method D applies the operator to x and to H.
      const BendingResult ra = BelkinMethod(all).compute(m.topology(), x, 1.0);
      const BendingResult rg = BelkinMethod(grid).compute(m.topology(), x, 1.0);
      const double dh = rel_max_diff(rg.H, ra.H);
      const double df = rel_max_diff(rg.force_density, ra.force_density);
      std::printf("[Belkin grid vs all, N_T=%d%s] rel. max diff Lap w %.2e, H %.2e, f %.2e\n", m.num_faces(),
                  deform ? " deformed" : "", dw, dh, df);
      EXPECT_LT(dw, 1e-8);
      EXPECT_LT(dh, 1e-8);
      EXPECT_LT(df, 1e-8);
      if (level == 3) {
        // With the reference's own cut (exponent 80) both keep the same terms: they differ by the
        // order of summation only.
        BelkinOptions same = grid;
        same.kernel_cutoff = std::exp(-80.0);
        const BelkinLaplacian ls(m.topology(), x, g, same);
        EXPECT_LT(rel_max_diff(ls.apply(x), la.apply(x)), 1e-12);
      }
    }
  }
}

TEST(BelkinLaplacian, KeptWeightsGiveTheSameSums) {
  // The grid form keeps its kernel weights for every apply when they fit weight_cache_bytes, else
  // computes them in each: the same terms summed in the same order, so the same numbers.
  BelkinOptions kept, recomputed;
  recomputed.weight_cache_bytes = 0;
  const TriMesh m = sphere_mesh(MeshFamily::MT1, 3);
  const Points x = deformed(rbc_points(m));
  const MeshGeometry g = MeshGeometry::compute(m.topology(), x);
  Scalars w(m.num_vertices());
  for (int i = 0; i < w.size(); ++i) w[i] = std::cos(2 * x(i, 2)) - x(i, 0);
  const BelkinLaplacian lk(m.topology(), x, g, kept), lr(m.topology(), x, g, recomputed);
  EXPECT_LE(rel_max_diff(lk.apply(w), lr.apply(w)), 1e-15);
  EXPECT_LE(rel_max_diff(lk.apply_to_positions(), lr.apply_to_positions()), 1e-15);
  EXPECT_LE(rel_max_diff(lk.apply(x), lr.apply(x)), 1e-15);
  const BendingResult rk = BelkinMethod(kept).compute(m.topology(), x, 1.0);
  const BendingResult rr = BelkinMethod(recomputed).compute(m.topology(), x, 1.0);
  EXPECT_LE(rel_max_diff(rk.force_density, rr.force_density), 1e-15);
}

TEST(BelkinLaplacian, PreparedForAnotherShapeEqualsAFreshOperator) {
  // prepare() rebuilds the cell list, the runs and the weights in the operator's own buffers (Method
  // D keeps one operator from call to call): the numbers are a fresh operator's, bit for bit, with
  // and without kept weights, and whether the second shape needs more or fewer of them.
  const TriMesh m = sphere_mesh(MeshFamily::MT1, 3);
  const Points a = rbc_points(m), b = deformed(a);
  const MeshGeometry ga = MeshGeometry::compute(m.topology(), a), gb = MeshGeometry::compute(m.topology(), b);
  Scalars w(m.num_vertices());
  for (int i = 0; i < w.size(); ++i) w[i] = std::sin(2 * b(i, 1)) + b(i, 0);
  auto same = [](const Eigen::MatrixXd& p, const Eigen::MatrixXd& q) {
    return p.rows() == q.rows() && p.cols() == q.cols() &&
           std::memcmp(p.data(), q.data(), sizeof(double) * p.size()) == 0;
  };
  for (const std::size_t cache_bytes : {std::size_t{1} << 30, std::size_t{0}}) {
    BelkinOptions o;
    o.weight_cache_bytes = cache_bytes;
    for (const bool forward : {true, false}) {
      const Points& first = forward ? a : b;
      const Points& second = forward ? b : a;
      const MeshGeometry& g1 = forward ? ga : gb;
      const MeshGeometry& g2 = forward ? gb : ga;
      BelkinLaplacian reused(m.topology(), first, g1, o);
      Scalars out;
      Points lap_x;
      reused.apply_into(w, out);
      reused.prepare(m.topology(), second, g2, o);
      reused.apply_into(w, out);
      reused.apply_to_positions_into(lap_x);
      const BelkinLaplacian fresh(m.topology(), second, g2, o);
      EXPECT_TRUE(same(out, fresh.apply(w))) << cache_bytes << " " << forward;
      EXPECT_TRUE(same(lap_x, fresh.apply_to_positions())) << cache_bytes << " " << forward;
    }
  }
}
