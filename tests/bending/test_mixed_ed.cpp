// Method ED: H, K and normal of Method E, Lap H by Belkin's operator (paper section 5).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "bendlab/bending/belkin.hpp"
#include "bendlab/bending/farutin.hpp"
#include "bendlab/bending/mixed_ed.hpp"
#include "bendlab/geometry/mesh_geometry.hpp"
#include "bendlab/mesh/generators.hpp"
#include "bendlab/surfaces/analytic_surface.hpp"

using namespace bendlab;

TEST(MixedED, NameAndOptions) {
  EXPECT_EQ(MixedEDMethod::create({})->name(), "ED");
  EXPECT_EQ(dynamic_cast<MixedEDMethod&>(*MixedEDMethod::create({})).rings(), 1);
  EXPECT_EQ(dynamic_cast<MixedEDMethod&>(*MixedEDMethod::create({{"rings", "3"}})).rings(), 3);
  EXPECT_THROW(MixedEDMethod::create({{"rings", "4"}}), Error);
  EXPECT_THROW(MixedEDMethod::create({{"half_space", "false"}}), Error);
}

TEST(MixedED, CurvatureFromEAndLaplacianFromD) {
  const TriMesh m = sphere_mesh(MeshFamily::MT1, 2);
  const Points x = make_rbc()->map_from_unit_sphere(m.positions());
  const double kb = 0.7;
  for (int rings : {1, 2}) {
    const BendingResult e = FarutinMethod(rings).compute(m.topology(), x, kb);
    const BendingResult ed = MixedEDMethod(rings).compute(m.topology(), x, kb);
    const MeshGeometry g = MeshGeometry::compute(m.topology(), x);
    const Scalars lap_d = belkin_laplacian(m.topology(), x, g, e.H);
    EXPECT_FALSE(ed.energy.has_value());
    double max_diff = 0;
    for (int i = 0; i < m.num_vertices(); ++i) {
      EXPECT_EQ(ed.H[i], e.H[i]);
      EXPECT_EQ(ed.K[i], e.K[i]);
      EXPECT_EQ(ed.normal.row(i), e.normal.row(i));
      EXPECT_EQ(ed.area[i], g.mixed_area[i]);
      EXPECT_EQ(ed.lapH[i], lap_d[i]);
      max_diff = std::max(max_diff, std::abs(ed.lapH[i] - e.lapH[i]));
      const double fn = 2 * kb * (ed.lapH[i] + 2 * ed.H[i] * (ed.H[i] * ed.H[i] - ed.K[i]));  // eq. (10)
      EXPECT_NEAR((ed.force_density.row(i) - fn * ed.normal.row(i)).norm(), 0.0, 1e-13 * (1 + std::abs(fn)));
      EXPECT_NEAR((ed.force.row(i) - ed.area[i] * ed.force_density.row(i)).norm(), 0.0,
                  1e-13 * (1 + ed.force.row(i).norm()));
    }
    // Two different operators: lapH is not E's (on the RBC |lapH| reaches ~100).
    EXPECT_GT(max_diff, 1e-3);
  }
}

TEST(MixedED, SphereLaplacianConverges) {
  // On the unit sphere lapH -> 0 and f -> 0: the averages decrease with every refinement.
  double prev_l = 1e9, prev_f = 1e9;
  for (int level = 2; level <= 5; ++level) {
    const TriMesh m = sphere_mesh(MeshFamily::MT1, level);
    const BendingResult r = MixedEDMethod().compute(m.topology(), m.positions(), 1.0);
    const int n = m.num_vertices();
    double l = 0, f = 0, lmax = 0;
    for (int i = 0; i < n; ++i) {
      l += std::abs(r.lapH[i]) / n;
      lmax = std::max(lmax, std::abs(r.lapH[i]));
      f += r.force_density.row(i).norm() / n;
    }
    std::printf("ED sphere MT1 level %d (N_T %d): |lapH| mean %.3e max %.3e, |f| mean %.3e\n", level, m.num_faces(),
                l, lmax, f);
    EXPECT_LT(l, prev_l);
    EXPECT_LT(f, prev_f);
    prev_l = l, prev_f = f;
  }
}

TEST(MixedED, RbcErrors) {
  // Figures for the record, and the same sign criterion as for Method E.
  const TriMesh m = sphere_mesh(MeshFamily::MT1, 4);
  const auto rbc = make_rbc();
  const Points x = rbc->map_from_unit_sphere(m.positions());
  const SurfaceFields a = rbc->evaluate(x, 1.0);
  const SurfaceMaxima mx = rbc->maxima(1.0);
  const BendingResult r = MixedEDMethod().compute(m.topology(), x, 1.0);
  const int n = m.num_vertices();
  double el = 0, ef = 0, el_max = 0, ef_max = 0;
  int strong = 0, agree = 0;
  for (int i = 0; i < n; ++i) {
    const double l = std::abs(r.lapH[i] - a.lapH[i]) / mx.lapH, f = (r.force_density.row(i) - a.f.row(i)).norm() / mx.f;
    el += l / n, ef += f / n;
    el_max = std::max(el_max, l), ef_max = std::max(ef_max, f);
    if (std::abs(a.f_normal[i]) > 0.1 * mx.f) {
      ++strong;
      agree += r.force_density.row(i).dot(a.f.row(i)) > 0;
    }
  }
  std::printf("ED on RBC N_T %d: eps_lapH mean %.3e max %.3e; eps_f mean %.3e max %.3e; sign agreement %d / %d\n",
              m.num_faces(), el, el_max, ef, ef_max, agree, strong);
  EXPECT_TRUE(r.force.allFinite());
  EXPECT_GT(agree, 0.9 * strong);
}
