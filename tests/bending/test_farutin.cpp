// Method E (Farutin et al.'s paraboloid fits, paper section 2.4.3).
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "bendlab/bending/farutin.hpp"
#include "bendlab/bending/mixed_ed.hpp"
#include "bendlab/geometry/mesh_geometry.hpp"
#include "bendlab/mesh/generators.hpp"
#include "bendlab/surfaces/analytic_surface.hpp"
#include "bending/shape_test_support.hpp"

using namespace bendlab;
using test_support::some_rotation;

namespace {

/// The graph z = g(x, y) = a x + b y + (alpha x^2 + 2 beta x y + gamma y^2) / 2 in a local frame,
/// placed in space by the rotation q and the origin o.
struct Quadric {
  double a, b, alpha, beta, gamma;
  Mat3 q = some_rotation();
  Vec3 o = Vec3(0.3, -1.2, 2.5);

  double z(double x, double y) const { return a * x + b * y + 0.5 * (alpha * x * x + gamma * y * y) + beta * x * y; }
  Vec3 point(double x, double y) const { return o + q * Vec3(x, y, z(x, y)); }
  /// Exact values at the origin for the normal on the +z side (Monge patch formulas).
  double w() const { return std::sqrt(1 + a * a + b * b); }
  Vec3 normal() const { return q * Vec3(-a, -b, 1) / w(); }
  double H() const {  // > 0 when the surface bends away from the normal, as a sphere does
    return -((1 + b * b) * alpha - 2 * a * b * beta + (1 + a * a) * gamma) / (2 * std::pow(w(), 3));
  }
  double K() const { return (alpha * gamma - beta * beta) / std::pow(w(), 4); }
};

/// Random chart points (x, y) in a disc of radius r around the origin, none at the origin.
std::vector<Eigen::Vector2d> chart_points(int count, double r, unsigned seed) {
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> ang(0, 2 * M_PI), rad(0.3 * r, r);
  std::vector<Eigen::Vector2d> p;
  for (int k = 0; k < count; ++k) {
    const double t = ang(gen), s = rad(gen);
    p.emplace_back(s * std::cos(t), s * std::sin(t));
  }
  return p;
}

struct ErrorStats {
  double mean = 0, max = 0;
  void add(double e, int n) {
    mean += e / n;
    max = std::max(max, e);
  }
};

}  // namespace

TEST(Farutin, NameAndOptions) {
  EXPECT_EQ(FarutinMethod::create({})->name(), "E");
  EXPECT_EQ(dynamic_cast<FarutinMethod&>(*FarutinMethod::create({})).rings(), 1);
  for (int r = 1; r <= 3; ++r)
    EXPECT_EQ(dynamic_cast<FarutinMethod&>(*FarutinMethod::create({{"rings", std::to_string(r)}})).rings(), r);
  for (const char* bad : {"0", "4", "-1", "1.5", "two", "", " 1"})
    EXPECT_THROW(FarutinMethod::create({{"rings", bad}}), Error) << bad;
  EXPECT_THROW(FarutinMethod::create({{"ring", "2"}}), Error);
  EXPECT_THROW(FarutinMethod(0), Error);
}

TEST(FarutinFit, ExactOnQuadricPatch) {
  // The fit is exact for any surface whose height above the chart plane is quadratic, also when
  // the normal guess (the chart's n0 = q e_z) is not the surface normal (a, b != 0).
  const Quadric cases[] = {{0, 0, 1.3, 0.4, -0.7}, {0.4, -0.25, 2.0, -0.3, 1.1}, {-1.1, 0.6, -0.5, 0.9, 0.2}};
  for (const Quadric& s : cases) {
    for (int count : {5, 6, 9}) {
      std::vector<Vec3> nb;
      for (const auto& p : chart_points(count, 0.2, 17u + count)) nb.push_back(s.point(p.x(), p.y()));
      const FarutinFit fit = farutin_fit_point(s.o, s.q.col(2), nb);
      ASSERT_TRUE(fit.valid());
      EXPECT_NEAR(fit.H, s.H(), 1e-10);
      EXPECT_NEAR(fit.K, s.K(), 1e-10);
      EXPECT_NEAR((fit.normal - s.normal()).norm(), 0.0, 1e-10);
      EXPECT_NEAR(fit.t1.cross(fit.t2).dot(fit.n0), 1.0, 1e-14);
    }
  }
}

TEST(FarutinFit, SphereCapGivesPositiveH) {
  // Points of a sphere of radius 2 around the node x0 = (0, 0, 2), outward guess e_z: H = 1/2,
  // K = 1/4 up to the truncation of the paraboloid (O(h^2) relative).
  const double r = 2, h = 1e-3;
  std::vector<Vec3> nb;
  for (int k = 0; k < 6; ++k) {
    const double t = k * M_PI / 3;
    nb.push_back(r * Vec3(std::sin(h) * std::cos(t), std::sin(h) * std::sin(t), std::cos(h)));
  }
  const FarutinFit fit = farutin_fit_point(Vec3(0, 0, r), Vec3(0, 0, 1), nb);
  EXPECT_NEAR(fit.H, 1 / r, 1e-6);
  EXPECT_NEAR(fit.K, 1 / (r * r), 1e-6);
  EXPECT_NEAR((fit.normal - Vec3(0, 0, 1)).norm(), 0.0, 1e-12);
  // A normal guess on the other side flips the normal and the sign of H, not K.
  const FarutinFit in = farutin_fit_point(Vec3(0, 0, r), Vec3(0, 0, -1), nb);
  EXPECT_NEAR(in.H, -fit.H, 1e-12);
  EXPECT_NEAR(in.K, fit.K, 1e-12);
  EXPECT_NEAR((in.normal + fit.normal).norm(), 0.0, 1e-12);
}

TEST(FarutinFit, UnderdeterminedNeighbourhoodsAreInvalid) {
  const Quadric s{0.1, 0.2, 1.0, 0.0, 1.0};
  std::vector<Vec3> four;
  for (const auto& p : chart_points(4, 0.2, 3u)) four.push_back(s.point(p.x(), p.y()));
  const FarutinFit few = farutin_fit_point(s.o, s.q.col(2), four);
  EXPECT_FALSE(few.valid());
  EXPECT_TRUE(std::isnan(few.H) && std::isnan(few.K) && std::isnan(few.normal.x()));
  // Seven neighbours on one line through the node: u^2, uv, v^2 are not independent there.
  std::vector<Vec3> line;
  for (int k = 1; k <= 7; ++k) line.push_back(s.point(0.03 * (k - 4.5), 0.0));
  EXPECT_FALSE(farutin_fit_point(s.o, s.q.col(2), line).valid());
}

TEST(FarutinFit, EqualsThreeComponentFit) {
  // The paper's procedure literally: fit each coordinate component x_l(u, v) separately (QR of the
  // m x 5 design matrix), then differential geometry with the vectors x_u, x_v, x_uu, x_uv, x_vv.
  // Points off any quadric, so the least-squares residual is not zero.
  std::mt19937 gen(11);
  std::normal_distribution<double> noise(0, 0.01);
  const Quadric s{0.3, -0.2, 1.5, 0.5, 0.8};
  std::vector<Vec3> nb;
  for (const auto& p : chart_points(11, 0.25, 5u))
    nb.push_back(s.point(p.x(), p.y()) + Vec3(noise(gen), noise(gen), noise(gen)));
  const Vec3 guess = (s.q * Vec3(0.1, -0.05, 1)).normalized();
  const FarutinFit fit = farutin_fit_point(s.o, guess, nb);
  ASSERT_TRUE(fit.valid());

  const int m = static_cast<int>(nb.size());
  Eigen::MatrixXd a(m, 5), d(m, 3);
  for (int j = 0; j < m; ++j) {
    const Vec3 r = nb[j] - s.o;
    const double u = r.dot(fit.t1), v = r.dot(fit.t2);
    a.row(j) << u, v, u * u / 2, u * v, v * v / 2;
    d.row(j) = r.transpose();
  }
  const Eigen::MatrixXd c = a.colPivHouseholderQr().solve(d);  // 5 x 3: row k = coefficient k of x, y, z
  const Vec3 xu = c.row(0), xv = c.row(1), xuu = c.row(2), xuv = c.row(3), xvv = c.row(4);
  Vec3 n = xu.cross(xv).normalized();
  if (n.dot(guess) < 0) n = -n;
  const double e = xu.dot(xu), f = xu.dot(xv), g = xv.dot(xv);
  const double l = xuu.dot(n), mm = xuv.dot(n), nn = xvv.dot(n);
  const double h_textbook = (e * nn - 2 * f * mm + g * l) / (2 * (e * g - f * f));
  const double k = (l * nn - mm * mm) / (e * g - f * f);
  EXPECT_NEAR(fit.H, -h_textbook, 1e-10);  // docs/conventions.md: the opposite sign of the textbook formula
  EXPECT_NEAR(fit.K, k, 1e-10);
  EXPECT_NEAR((fit.normal - n).norm(), 0.0, 1e-12);
}

TEST(FarutinFit, LaplacianExactForQuadraticField) {
  // On a quadric patch z = g(x, y) (chart = the local (x, y) plane, n0 = q e_z) and a field w
  // quadratic in (x, y), the fit of w is exact, so the Laplace-Beltrami operator at the node is
  // exact: g^ab (w_ab - Gamma^c_ab w_c), Gamma^c_ab = g^cd x_d . x_ab, all from the exact surface.
  const double w0 = 0.7, p = -1.3, qq = 0.4, r = 2.1, s_ = -0.6, t = 0.9;
  auto field = [&](double x, double y) { return w0 + p * x + qq * y + 0.5 * r * x * x + s_ * x * y + 0.5 * t * y * y; };
  const Quadric cases[] = {{0, 0, 0, 0, 0}, {0.5, -0.3, 0, 0, 0}, {0.4, -0.25, 2.0, -0.3, 1.1}};
  for (const Quadric& sf : cases) {
    std::vector<Vec3> nb;
    std::vector<double> wv;
    for (const auto& c : chart_points(8, 0.2, 23u)) {
      nb.push_back(sf.point(c.x(), c.y()));
      wv.push_back(field(c.x(), c.y()));
    }
    const FarutinFit fit = farutin_fit_point(sf.o, sf.q.col(2), nb);
    ASSERT_TRUE(fit.valid());
    const double lap = farutin_laplacian_point(fit, sf.o, nb, w0, wv);

    // Exact value in the local (x, y) parametrisation.
    const Vec3 xd[2] = {Vec3(1, 0, sf.a), Vec3(0, 1, sf.b)};
    const Vec3 xdd[2][2] = {{Vec3(0, 0, sf.alpha), Vec3(0, 0, sf.beta)}, {Vec3(0, 0, sf.beta), Vec3(0, 0, sf.gamma)}};
    Eigen::Matrix2d g;
    for (int i = 0; i < 2; ++i)
      for (int j = 0; j < 2; ++j) g(i, j) = xd[i].dot(xd[j]);
    const Eigen::Matrix2d gi = g.inverse();
    const Eigen::Vector2d dw(p, qq);
    Eigen::Matrix2d ddw;
    ddw << r, s_, s_, t;
    double exact = 0;
    for (int a = 0; a < 2; ++a)
      for (int b = 0; b < 2; ++b) {
        double gw = 0;  // Gamma^c_ab w_c
        for (int c = 0; c < 2; ++c)
          for (int d = 0; d < 2; ++d) gw += gi(c, d) * xd[d].dot(xdd[a][b]) * dw[c];
        exact += gi(a, b) * (ddw(a, b) - gw);
      }
    if (sf.alpha == 0 && sf.a == 0) {
      EXPECT_NEAR(exact, r + t, 1e-14);  // flat chart: the trace
    }
    EXPECT_NEAR(lap, exact, 1e-9 * (1 + std::abs(exact)));
  }
}

TEST(Farutin, ResultLayoutAndConversion) {
  const TriMesh m = sphere_mesh(MeshFamily::MT1, 2);
  const Points x = make_rbc()->map_from_unit_sphere(m.positions());
  const double kb = 0.3;
  const BendingResult r = FarutinMethod().compute(m.topology(), x, kb);
  const MeshGeometry g = MeshGeometry::compute(m.topology(), x);
  const std::vector<FarutinFit> fits = farutin_fit(m.topology(), x, g.normal_mwa, 1);
  const int n = m.num_vertices();
  ASSERT_EQ(r.H.size(), n);
  ASSERT_EQ(r.force.rows(), n);
  EXPECT_FALSE(r.energy.has_value());
  for (int i = 0; i < n; ++i) {
    EXPECT_EQ(r.area[i], g.mixed_area[i]);
    EXPECT_EQ(r.H[i], fits[i].H);
    EXPECT_EQ(r.K[i], fits[i].K);
    EXPECT_NEAR(r.normal.row(i).norm(), 1.0, 1e-14);
    EXPECT_GT(r.normal.row(i).dot(g.normal_mwa.row(i)), 0.9);
    const double fn = 2 * kb * (r.lapH[i] + 2 * r.H[i] * (r.H[i] * r.H[i] - r.K[i]));  // eq. (10)
    EXPECT_NEAR((r.force_density.row(i) - fn * r.normal.row(i)).norm(), 0.0, 1e-13 * (1 + std::abs(fn)));
    EXPECT_NEAR((r.force.row(i) - r.area[i] * r.force_density.row(i)).norm(), 0.0,
                1e-13 * (1 + r.force.row(i).norm()));  // eq. (14)
  }
}

TEST(Farutin, SphereConverges) {
  // H -> 1/R, K -> 1/R^2, f -> 0 on the unit sphere (MT1): the average errors decrease with
  // every refinement.
  double prev_h = 1e9, prev_k = 1e9, prev_f = 1e9;
  for (int level = 2; level <= 5; ++level) {
    const TriMesh m = sphere_mesh(MeshFamily::MT1, level);
    const BendingResult r = FarutinMethod().compute(m.topology(), m.positions(), 1.0);
    const int n = m.num_vertices();
    ErrorStats eh, ek, ef, en;
    for (int i = 0; i < n; ++i) {
      eh.add(std::abs(r.H[i] - 1), n);
      ek.add(std::abs(r.K[i] - 1), n);
      ef.add(r.force_density.row(i).norm(), n);
      en.add((r.normal.row(i) - m.positions().row(i)).norm(), n);
    }
    std::printf("E sphere MT1 level %d (N_T %d): |H-1| mean %.3e max %.3e, |K-1| mean %.3e, |f| mean %.3e max %.3e, "
                "|n-n_a| mean %.3e\n",
                level, m.num_faces(), eh.mean, eh.max, ek.mean, ef.mean, ef.max, en.mean);
    EXPECT_LT(eh.mean, prev_h);
    EXPECT_LT(ek.mean, prev_k);
    EXPECT_LT(ef.mean, prev_f);
    prev_h = eh.mean, prev_k = ek.mean, prev_f = ef.mean;
  }
  EXPECT_LT(prev_h, 1e-3);
}

TEST(Farutin, LargerRingsAndLowValence) {
  // rings 2 and 3 on the RBC; and the octahedron family, whose valence-4 nodes need ring 2.
  const TriMesh m = sphere_mesh(MeshFamily::MT1, 4);
  const Points x = make_rbc()->map_from_unit_sphere(m.positions());
  const auto rbc = make_rbc();
  for (int rings = 1; rings <= 3; ++rings) {
    const BendingResult r = FarutinMethod(rings).compute(m.topology(), x, 1.0);
    ASSERT_TRUE(r.force.allFinite() && r.H.allFinite() && r.K.allFinite() && r.lapH.allFinite()) << rings;
    const MeshGeometry g = MeshGeometry::compute(m.topology(), x);
    const std::vector<FarutinFit> fits = farutin_fit(m.topology(), x, g.normal_mwa, rings);
    double eh = 0;
    for (int i = 0; i < m.num_vertices(); ++i) {
      EXPECT_EQ(fits[i].rings, rings);
      eh += std::abs(r.H[i] - rbc->at(x.row(i).transpose()).H) / rbc->maxima().H / m.num_vertices();
    }
    std::printf("E rings %d on RBC N_T %d: mean eps_H %.3e\n", rings, m.num_faces(), eh);
    EXPECT_LT(eh, 0.05);
  }

  const TriMesh octa = sphere_mesh(MeshFamily::Octa, 3);
  const MeshGeometry g = MeshGeometry::compute(octa.topology(), octa.positions());
  const std::vector<FarutinFit> fits = farutin_fit(octa.topology(), octa.positions(), g.normal_mwa, 1);
  int extended = 0;
  for (int i = 0; i < octa.num_vertices(); ++i) {
    ASSERT_TRUE(fits[i].valid());
    EXPECT_EQ(fits[i].rings, octa.topology().valence(i) < 5 ? 2 : 1);
    extended += fits[i].rings == 2;
  }
  EXPECT_EQ(extended, 6);  // the octahedron's vertices keep valence 4
  const BendingResult r = FarutinMethod().compute(octa.topology(), octa.positions(), 1.0);
  EXPECT_TRUE(r.force.allFinite());
  for (int i = 0; i < octa.num_vertices(); ++i) EXPECT_NEAR(r.H[i], 1.0, 0.1);
}

TEST(Farutin, MeshWithoutAnyValidFitIsRefusedNamingTheVertex) {
  // The bare octahedron: every vertex sees the four at distance sqrt(2) and the opposite one on
  // its own normal line, so the xy coefficient of the paraboloid is free at every support size.
  // E and ED refuse it with a named error instead of returning NaN forces.
  const TriMesh octa = octahedron();
  for (const bool mixed : {false, true}) {
    try {
      if (mixed)
        (void)MixedEDMethod().compute(octa.topology(), octa.positions(), 1.0);
      else
        (void)FarutinMethod().compute(octa.topology(), octa.positions(), 1.0);
      ADD_FAILURE() << "the octahedron was accepted";
    } catch (const Error& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(mixed ? "method ED" : "method E"), std::string::npos) << what;
      EXPECT_NE(what.find("vertex 0"), std::string::npos) << what;
    }
  }
}

TEST(Farutin, IndependentOfThreadCount) {
  // Every node's fit reads only its own neighbourhood: the results are bitwise the same.
  const TriMesh m = sphere_mesh(MeshFamily::MT1, 3);
  const Points x = make_rbc()->map_from_unit_sphere(m.positions());
  const int threads = omp_get_max_threads();
  omp_set_num_threads(1);
  const BendingResult one = FarutinMethod(2).compute(m.topology(), x, 1.0);
  omp_set_num_threads(4);
  const BendingResult four = FarutinMethod(2).compute(m.topology(), x, 1.0);
  omp_set_num_threads(threads);
  EXPECT_EQ(one.force, four.force);
  EXPECT_EQ(one.H, four.H);
  EXPECT_EQ(one.lapH, four.lapH);
}

TEST(Farutin, ScalingAndRotation) {
  const TriMesh m = sphere_mesh(MeshFamily::MT1, 2);
  const Points x = make_rbc()->map_from_unit_sphere(m.positions());
  const FarutinMethod e;
  const BendingResult r = e.compute(m.topology(), x, 1.0);
  const double s = 3.7;
  const BendingResult rs = e.compute(m.topology(), s * x, 1.0);
  const Mat3 q = some_rotation();
  const Points xr = x * q.transpose();  // row i -> q x_i
  const BendingResult rr = e.compute(m.topology(), xr, 1.0);
  const double tol = 1e-9;
  for (int i = 0; i < m.num_vertices(); ++i) {
    // H ~ 1/s, K ~ 1/s^2, lapH and f ~ 1/s^3, F = f A ~ 1/s.
    EXPECT_NEAR(s * rs.H[i], r.H[i], tol * (1 + std::abs(r.H[i])));
    EXPECT_NEAR(s * s * rs.K[i], r.K[i], tol * (1 + std::abs(r.K[i])));
    EXPECT_NEAR(s * s * s * rs.lapH[i], r.lapH[i], tol * (1 + std::abs(r.lapH[i])));
    EXPECT_NEAR((s * s * s * rs.force_density.row(i) - r.force_density.row(i)).norm(), 0.0,
                tol * (1 + r.force_density.row(i).norm()));
    EXPECT_NEAR((s * rs.force.row(i) - r.force.row(i)).norm(), 0.0, tol * (1 + r.force.row(i).norm()));
    EXPECT_NEAR((rs.normal.row(i) - r.normal.row(i)).norm(), 0.0, tol);
    // Rotation: scalars unchanged, vectors rotated.
    EXPECT_NEAR(rr.H[i], r.H[i], tol * (1 + std::abs(r.H[i])));
    EXPECT_NEAR(rr.K[i], r.K[i], tol * (1 + std::abs(r.K[i])));
    EXPECT_NEAR(rr.lapH[i], r.lapH[i], tol * (1 + std::abs(r.lapH[i])));
    EXPECT_NEAR((rr.normal.row(i).transpose() - q * r.normal.row(i).transpose()).norm(), 0.0, tol);
    EXPECT_NEAR((rr.force_density.row(i).transpose() - q * r.force_density.row(i).transpose()).norm(), 0.0,
                tol * (1 + r.force_density.row(i).norm()));
  }
}

TEST(Farutin, RbcAgainstAnalytic) {
  // 5120-triangle RBC: f has the analytic sign wherever |f_a| > 10% of its maximum (at > 90% of
  // those nodes), and the average H error (eq. 17) is below Method C's cotangent H.
  const TriMesh m = sphere_mesh(MeshFamily::MT1, 4);
  const auto rbc = make_rbc();
  const Points x = rbc->map_from_unit_sphere(m.positions());
  const SurfaceFields a = rbc->evaluate(x, 1.0);
  const SurfaceMaxima mx = rbc->maxima(1.0);
  const BendingResult r = FarutinMethod().compute(m.topology(), x, 1.0);
  const MeshGeometry g = MeshGeometry::compute(m.topology(), x);
  const Scalars h_cot = mean_curvature_cotan(m.topology(), g, x, g.normal_mwa, g.mixed_area);

  const int n = m.num_vertices();
  ErrorStats eh, ehc, ek, el, ef, en;
  int strong = 0, agree = 0;
  for (int i = 0; i < n; ++i) {
    eh.add(std::abs(r.H[i] - a.H[i]) / mx.H, n);
    ehc.add(std::abs(h_cot[i] - a.H[i]) / mx.H, n);
    ek.add(std::abs(r.K[i] - a.K[i]) / mx.K, n);
    el.add(std::abs(r.lapH[i] - a.lapH[i]) / mx.lapH, n);
    ef.add((r.force_density.row(i) - a.f.row(i)).norm() / mx.f, n);
    en.add((r.normal.row(i) - a.normal.row(i)).norm(), n);
    if (std::abs(a.f_normal[i]) > 0.1 * mx.f) {
      ++strong;
      agree += r.force_density.row(i).dot(a.f.row(i)) > 0;
    }
  }
  std::printf("E on RBC N_T %d: eps_n mean %.3e max %.3e; eps_H mean %.3e max %.3e (C: mean %.3e max %.3e); "
              "eps_K mean %.3e max %.3e; eps_lapH mean %.3e max %.3e; eps_f mean %.3e max %.3e; "
              "sign agreement %d / %d\n",
              m.num_faces(), en.mean, en.max, eh.mean, eh.max, ehc.mean, ehc.max, ek.mean, ek.max, el.mean, el.max,
              ef.mean, ef.max, agree, strong);
  ASSERT_GT(strong, 0);
  EXPECT_GT(agree, 0.9 * strong);
  EXPECT_LT(eh.mean, ehc.mean);
}
