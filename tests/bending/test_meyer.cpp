// Method C (Meyer et al.'s cotangent operators, paper section 2.4.1).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "bendlab/bending/meyer.hpp"
#include "bendlab/geometry/mesh_geometry.hpp"
#include "bendlab/mesh/generators.hpp"
#include "bendlab/surfaces/analytic_surface.hpp"
#include "bending/rbc_test_support.hpp"
#include "bending/shape_test_support.hpp"

using namespace bendlab;
using test_support::some_rotation;

namespace {

struct SphereErrors {
  double h_mean = 0, h_max = 0;  ///< |H - 1/R|
  double f_mean = 0, f_max = 0;  ///< |f| (exactly 0 on a sphere)
  int f_argmax = -1;
};

SphereErrors sphere_errors(const TriMesh& m, const BendingResult& r, double radius) {
  SphereErrors e;
  const int n = m.num_vertices();
  for (int i = 0; i < n; ++i) {
    const double eh = std::abs(r.H[i] - 1.0 / radius), ef = r.force_density.row(i).norm();
    e.h_mean += eh / n;
    e.f_mean += ef / n;
    e.h_max = std::max(e.h_max, eh);
    if (ef > e.f_max) e.f_max = ef, e.f_argmax = i;
  }
  return e;
}

}  // namespace

TEST(Meyer, NameAndOptions) {
  EXPECT_EQ(MeyerMethod::create({})->name(), "C");
  EXPECT_THROW(MeyerMethod::create({{"rings", "2"}}), Error);
}

TEST(Meyer, ResultLayoutAndConversion) {
  const TriMesh m = sphere_mesh(MeshFamily::MT2, 2);
  const Points x = 1.7 * m.positions();
  const double kb = 0.3;
  const BendingResult r = MeyerMethod().compute(m.topology(), x, kb);
  const MeshGeometry g = MeshGeometry::compute(m.topology(), x);
  const int n = m.num_vertices();
  ASSERT_EQ(r.H.size(), n);
  ASSERT_EQ(r.force.rows(), n);
  EXPECT_FALSE(r.energy.has_value());
  EXPECT_FALSE(MeyerMethod().energy(m.topology(), x, kb).has_value());
  for (int i = 0; i < n; ++i) {
    EXPECT_EQ(r.area[i], g.mixed_area[i]);
    EXPECT_EQ(r.K[i], g.gaussian_curvature[i]);                          // eq. (12)
    EXPECT_EQ(r.normal.row(i), g.normal_mwa.row(i));                     // MWA normal
    const double fn = 2 * kb * (r.lapH[i] + 2 * r.H[i] * (r.H[i] * r.H[i] - r.K[i]));  // eq. (10)
    EXPECT_NEAR((r.force_density.row(i) - fn * r.normal.row(i)).norm(), 0.0, 1e-14 * (1 + std::abs(fn)));
    EXPECT_NEAR((r.force.row(i) - r.area[i] * r.force_density.row(i)).norm(), 0.0,
                1e-14 * (1 + r.force.row(i).norm()));  // eq. (14)
  }
  Points f;
  MeyerMethod().forces(m.topology(), x, kb, f);
  EXPECT_EQ(f, r.force);
}

TEST(Meyer, LaplacianOfConstantIsExactlyZero) {
  const TriMesh m = sphere_mesh(MeshFamily::MT1, 3);
  const Points x = make_rbc()->map_from_unit_sphere(m.positions());
  const MeshGeometry g = MeshGeometry::compute(m.topology(), x);
  const Scalars lap = cotan_laplacian(m.topology(), g, Scalars(Scalars::Constant(m.num_vertices(), 3.25)), g.mixed_area);
  for (int i = 0; i < m.num_vertices(); ++i) EXPECT_EQ(lap[i], 0.0);
}

// H -> 1/R and f -> 0 on spheres of both families: the average errors shrink with every
// refinement, overall at least at first order (h halves per level: factor 8 from 320 to 20480
// triangles). On MT1 the force density keeps a finite error at the 12 five-valent nodes (the
// systematic maximal error of Method C, paper section 3): from 5120 triangles on the largest
// |f| sits at one of them, and there it no longer shrinks with the mean.
TEST(Meyer, SphereConvergence) {
  const double radius = 2.0;
  for (MeshFamily fam : {MeshFamily::MT1, MeshFamily::MT2}) {
    std::vector<SphereErrors> errs;
    std::vector<double> max_at_five;  // largest |f| over the five-valent nodes
    for (int level = 2; level <= 5; ++level) {
      const TriMesh m = sphere_mesh(fam, level);
      const Points x = radius * m.positions();
      const BendingResult r = MeyerMethod().compute(m.topology(), x, 1.0);
      const SphereErrors e = sphere_errors(m, r, radius);
      double f5 = 0;
      for (int i = 0; i < m.num_vertices(); ++i)
        if (m.topology().valence(i) == 5) f5 = std::max(f5, r.force_density.row(i).norm());
      std::printf("[Meyer sphere R=%g %s N_T=%d] |H - 1/R| mean %.3e max %.3e | |f| mean %.3e max %.3e "
                  "(at valence %d), max at five-valent nodes %.3e\n",
                  radius, to_string(fam).c_str(), m.num_faces(), e.h_mean, e.h_max, e.f_mean, e.f_max,
                  m.topology().valence(e.f_argmax), f5);
      if (!errs.empty()) {
        EXPECT_LT(e.h_mean, errs.back().h_mean) << to_string(fam) << " level " << level;
        EXPECT_LT(e.f_mean, errs.back().f_mean) << to_string(fam) << " level " << level;
      }
      if (fam == MeshFamily::MT1 && level >= 4) {
        EXPECT_EQ(m.topology().valence(e.f_argmax), 5) << level;
      }
      errs.push_back(e);
      max_at_five.push_back(f5);
    }
    EXPECT_LT(errs.back().f_mean, errs.front().f_mean / 8) << to_string(fam);
    EXPECT_LT(errs.back().h_mean, errs.front().h_mean / 8) << to_string(fam);
    if (fam == MeshFamily::MT1) {
      // The mean drops about fourfold from 5120 to 20480 triangles; the five-valent error does not.
      EXPECT_GT(max_at_five[3], 0.5 * max_at_five[2]);
      EXPECT_GT(max_at_five[3], 4 * errs.back().f_mean);
    }
  }
}

// Under x -> s x: H ~ 1/s, K ~ 1/s^2, lapH and f ~ 1/s^3, F ~ 1/s. Under a rotation Q: scalars
// unchanged, vectors rotated.
TEST(Meyer, ScalingAndRotation) {
  const TriMesh m = sphere_mesh(MeshFamily::MT1, 2);
  const Points x = make_rbc()->map_from_unit_sphere(m.positions());
  const BendingResult r = MeyerMethod().compute(m.topology(), x, 1.0);
  const double fmax = r.force_density.rowwise().norm().maxCoeff();
  const double hmax = r.H.cwiseAbs().maxCoeff();
  for (double s : {1e-3, 1e3}) {
    const BendingResult rs = MeyerMethod().compute(m.topology(), s * x, 1.0);
    EXPECT_LT((s * rs.H - r.H).cwiseAbs().maxCoeff(), 1e-12 * hmax) << s;
    EXPECT_LT((s * s * rs.K - r.K).cwiseAbs().maxCoeff(), 1e-12 * hmax * hmax) << s;
    EXPECT_LT((s * s * s * rs.force_density - r.force_density).rowwise().norm().maxCoeff(), 1e-11 * fmax) << s;
    EXPECT_LT((s * rs.force - r.force).rowwise().norm().maxCoeff(), 1e-11 * r.force.rowwise().norm().maxCoeff());
  }
  const Mat3 Q = some_rotation();
  const Points xr = x * Q.transpose();
  const BendingResult rr = MeyerMethod().compute(m.topology(), xr, 1.0);
  EXPECT_LT((rr.H - r.H).cwiseAbs().maxCoeff(), 1e-12 * hmax);
  EXPECT_LT((rr.force_density - r.force_density * Q.transpose()).rowwise().norm().maxCoeff(), 1e-11 * fmax);
}

// The 5120-triangle RBC (docs/conventions.md §4): sign of f against the analytic f where the
// latter is not small, and the average relative error of H, eq. (17).
TEST(Meyer, RedBloodCell5120) {
  const auto a = test_support::rbc_agreement_5120(MeyerMethod(), "Meyer");
  EXPECT_LT(a.eh_mean, 0.05);
  EXPECT_GT(a.fraction(), 0.9);
}
