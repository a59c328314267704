#include "bendlab/surfaces/analytic_surface.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <random>
#include <nlohmann/json.hpp>
#include <vector>

#include "bendlab/surfaces/surface_of_revolution.hpp"

namespace {

using namespace bendlab;
constexpr double kPi = 3.14159265358979323846;

const SurfaceOfRevolution& revolution(const AnalyticSurface& s) {
  return dynamic_cast<const SurfaceOfRevolution&>(s);
}

// Gauss-Legendre nodes and weights on [-1, 1] by Newton's method on P_n.
void gauss_legendre(int n, std::vector<double>& x, std::vector<double>& w) {
  x.assign(n, 0.0);
  w.assign(n, 0.0);
  for (int i = 0; i < n; ++i) {
    double z = std::cos(kPi * (i + 0.75) / (n + 0.5)), dp = 0.0;
    for (int it = 0; it < 100; ++it) {
      double p0 = 1.0, p1 = z;
      for (int k = 2; k <= n; ++k) {
        const double p2 = ((2.0 * k - 1.0) * z * p1 - (k - 1.0) * p0) / k;
        p0 = p1;
        p1 = p2;
      }
      dp = n * (z * p1 - p0) / (z * z - 1.0);
      const double dz = p1 / dp;
      z -= dz;
      if (std::abs(dz) < 1e-16) break;
    }
    x[i] = z;
    w[i] = 2.0 / ((1.0 - z * z) * dp * dp);
  }
}

// Integral over the surface of g(meridian values), dA = 2 pi r s' dt, by composite
// 20-point Gauss-Legendre on 64 panels of [0, pi].
template <class G>
double surface_integral(const SurfaceOfRevolution& s, G&& g) {
  std::vector<double> x, w;
  gauss_legendre(20, x, w);
  const int panels = 64;
  const double h = kPi / panels;
  double sum = 0.0;
  for (int p = 0; p < panels; ++p)
    for (std::size_t i = 0; i < x.size(); ++i) {
      const double t = h * (p + 0.5 * (x[i] + 1.0));
      const MeridianValues m = s.meridian(t);
      sum += 0.5 * h * w[i] * g(m) * 2.0 * kPi * m.r * m.ds_dt;
    }
  return sum;
}

Vec3 unit_point(double t, double phi) {
  return Vec3(std::sin(t) * std::cos(phi), std::sin(t) * std::sin(phi), std::cos(t));
}

Vec3 mapped(const AnalyticSurface& s, const Vec3& u) {
  Points p(1, 3);
  p.row(0) = u.transpose();
  return row(s.map_from_unit_sphere(p), 0);
}

TEST(AnalyticSurface, GaussLegendreRuleIsExact) {
  std::vector<double> x, w;
  gauss_legendre(20, x, w);
  double s0 = 0, s38 = 0;
  for (int i = 0; i < 20; ++i) {
    s0 += w[i];
    s38 += w[i] * std::pow(x[i], 38);
  }
  EXPECT_NEAR(s0, 2.0, 1e-14);
  EXPECT_NEAR(s38, 2.0 / 39.0, 1e-14);
}

TEST(Rbc, ReproducesReferencePoints) {
  std::ifstream in(std::string(BENDLAB_TEST_DATA_DIR) + "/rbc_points.json");
  ASSERT_TRUE(in.good());
  const nlohmann::json data = nlohmann::json::parse(in);
  const auto rbc = make_rbc(1.0);
  ASSERT_GE(data["points"].size(), 10u);
  for (const auto& p : data["points"]) {
    const Vec3 x(p["x"].get<double>(), p["y"].get<double>(), p["z"].get<double>());
    const SurfaceValues v = rbc->at(x);
    const double t = p["t"].get<double>();
    SCOPED_TRACE("t = " + std::to_string(t));
    EXPECT_NEAR(revolution(*rbc).parameter_of(x), t, 1e-12);
    for (const auto& [name, got] : {std::pair{"H", v.H}, std::pair{"K", v.K},
                                    std::pair{"lapH", v.lapH}, std::pair{"f_normal", v.f_normal}}) {
      const double want = p[name].get<double>();
      EXPECT_NEAR(got, want, 1e-10 * std::abs(want)) << name;
    }
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(v.normal[k], p["n"][k].get<double>(), 1e-12);
      EXPECT_NEAR(v.f[k], v.f_normal * v.normal[k], 1e-15 * std::abs(v.f_normal));
    }
  }
}

TEST(Rbc, MaximaMatchStatedValues) {
  // docs/conventions.md §3 states them to 6 significant digits (R = 1, kB = 1).
  const SurfaceMaxima m = make_rbc(1.0)->maxima();
  EXPECT_NEAR(m.H, 2.20098, 0.5e-5);
  EXPECT_NEAR(m.K, 3.60620, 0.5e-5);
  EXPECT_NEAR(m.lapH, 109.095, 0.5e-3);
  EXPECT_NEAR(m.f, 189.457, 0.5e-3);
}

TEST(Rbc, MaximaDominateSamplesAndScaleWithRadiusAndKb) {
  const auto rbc = make_rbc(1.0);
  const SurfaceMaxima m = rbc->maxima();
  for (int i = 0; i <= 997; ++i) {
    const MeridianValues v = revolution(*rbc).meridian(kPi * i / 997);
    EXPECT_LE(std::abs(v.H), m.H * (1 + 1e-14));
    EXPECT_LE(std::abs(v.lapH), m.lapH * (1 + 1e-14));
    EXPECT_LE(std::abs(v.f_normal_per_kb()), m.f * (1 + 1e-14));
  }
  // H ~ 1/R, K ~ 1/R^2, lapH and f ~ kB / R^3.
  const SurfaceMaxima m2 = make_rbc(2.0)->maxima(3.0);
  EXPECT_NEAR(m2.H, m.H / 2, 1e-9 * m.H);
  EXPECT_NEAR(m2.K, m.K / 4, 1e-9 * m.K);
  EXPECT_NEAR(m2.lapH, m.lapH / 8, 1e-9 * m.lapH);
  EXPECT_NEAR(m2.f, 3.0 * m.f / 8, 1e-9 * m.f);
}

TEST(Rbc, PoleValuesHaveClosedForm) {
  // Near the pole z = R C0/2 + (C1 - C0/2) r^2 / (2R): an upward-curving cap under an upward
  // normal, so c1 = c2 = -(C1 - C0/2)/R.
  for (double R : {1.0, 0.25, 7.0}) {
    const auto rbc = make_rbc(R);
    const double c = -(kRbcC1 - kRbcC0 / 2) / R;
    for (double zsign : {1.0, -1.0}) {
      const SurfaceValues v = rbc->at(Vec3(0, 0, zsign * R * kRbcC0 / 2));
      EXPECT_NEAR(v.H, c, 1e-14 * std::abs(c));
      EXPECT_NEAR(v.K, c * c, 1e-14 * c * c);
      EXPECT_NEAR(v.normal.z(), zsign, 1e-15);
    }
  }
}

TEST(Rbc, GaussBonnetAndZeroMeanLaplacian) {
  const auto owner = make_rbc(1.0);
  const auto& rbc = revolution(*owner);
  EXPECT_NEAR(surface_integral(rbc, [](const MeridianValues& m) { return m.K; }), 4 * kPi, 1e-11);
  const double abs_lap = surface_integral(rbc, [](const MeridianValues& m) { return std::abs(m.lapH); });
  EXPECT_NEAR(surface_integral(rbc, [](const MeridianValues& m) { return m.lapH; }), 0.0,
              1e-11 * abs_lap);
}

TEST(Rbc, ContinuousAtBothPoles) {
  const auto rbc = make_rbc(1.0);
  const SurfaceMaxima mx = rbc->maxima();
  for (double pole : {0.0, kPi}) {
    const SurfaceValues v0 = rbc->at(mapped(*rbc, unit_point(pole, 0)));
    auto diff = [&](double u) {
      const double t = pole == 0.0 ? u : kPi - u;
      const SurfaceValues v = rbc->at(mapped(*rbc, unit_point(t, 0.3)));
      return std::array<double, 4>{(v.H - v0.H) / mx.H, (v.K - v0.K) / mx.K,
                                   (v.lapH - v0.lapH) / mx.lapH, (v.f_normal - v0.f_normal) / mx.f};
    };
    const auto d9 = diff(1e-9), d6 = diff(1e-6), d3 = diff(1e-3), d3b = diff(2e-3);
    for (int k = 0; k < 4; ++k) {
      SCOPED_TRACE("pole " + std::to_string(pole) + ", quantity " + std::to_string(k));
      // Even about the pole: the difference is a u^2 + O(u^4), with |a| of order 1e2 here.
      EXPECT_LE(std::abs(d9[k]), 1e-13);
      EXPECT_LE(std::abs(d6[k]), 1e-8);
      // Quadratic onset: no O(u) or O(1/u) noise left at u = 1e-3.
      EXPECT_NEAR(d3b[k] / 4e-6, d3[k] / 1e-6, 1e-2 * std::abs(d3[k] / 1e-6) + 1e-4);
    }
  }
}

TEST(Rbc, MapPutsPointsOnSurfaceWithTheirParameter) {
  for (double R : {1.0, 3.5}) {
    const auto rbc = make_rbc(R);
    const auto& rev = revolution(*rbc);
    for (double t : {0.0, 1e-7, 0.2, 0.9, kPi / 2, 1.3, 2.5, kPi - 1e-7, kPi}) {
      const Vec3 x = mapped(*rbc, unit_point(t, 1.1));
      const double rho = std::hypot(x.x(), x.y()) / R;
      const double P = kRbcC0 + kRbcC1 * rho * rho + kRbcC2 * std::pow(rho, 4);
      // Implicit form of eq. (15): (2 z / (R P))^2 + rho^2 = 1.
      EXPECT_NEAR(std::pow(2 * x.z() / (R * P), 2) + rho * rho, 1.0, 1e-14);
      EXPECT_NEAR(rev.parameter_of(x), t, 1e-12);
      const SurfaceValues a = rbc->at(x), b = rev.at_angles(t, 1.1);
      EXPECT_NEAR(a.H, b.H, 1e-11 * rbc->maxima().H);
      EXPECT_NEAR(a.lapH, b.lapH, 1e-11 * rbc->maxima().lapH);
      EXPECT_NEAR((a.normal - b.normal).norm(), 0.0, 1e-12);
    }
  }
}

TEST(Rbc, EvaluateMatchesAtRowByRow) {
  const auto rbc = make_rbc(1.0);
  Points u(50, 3);
  for (int i = 0; i < 50; ++i) u.row(i) = unit_point(kPi * i / 49, 0.7 * i).transpose();
  const Points x = rbc->map_from_unit_sphere(u);
  const SurfaceFields f = rbc->evaluate(x, 2.5);
  for (int i = 0; i < 50; ++i) {
    const SurfaceValues v = rbc->at(row(x, i), 2.5);
    EXPECT_EQ(f.H[i], v.H);
    EXPECT_EQ(f.lapH[i], v.lapH);
    EXPECT_EQ(f.f_normal[i], v.f_normal);
    EXPECT_EQ((row(f.f, i) - v.f).norm(), 0.0);
    EXPECT_EQ((row(f.normal, i) - v.normal).norm(), 0.0);
  }
}

TEST(Rbc, ForceScalesLinearlyWithKb) {
  const auto rbc = make_rbc(1.0);
  const Vec3 x = mapped(*rbc, unit_point(0.8, 0.2));
  const SurfaceValues v1 = rbc->at(x, 1.0), v3 = rbc->at(x, 3.0);
  EXPECT_DOUBLE_EQ(v3.f_normal, 3.0 * v1.f_normal);
  EXPECT_NEAR((v3.f - 3.0 * v1.f).norm(), 0.0, 1e-13 * v1.f.norm());
  EXPECT_EQ(v3.H, v1.H);
  EXPECT_EQ(v3.lapH, v1.lapH);
}

TEST(Sphere, ExactValuesForAnyRadius) {
  for (double R : {1e-6, 0.3, 1.0, 17.0, 1e6}) {
    const auto s = make_sphere(R);
    for (double t : {0.0, 1e-9, 0.4, kPi / 2, 2.2, kPi}) {
      const Vec3 x = mapped(*s, unit_point(t, 0.9));
      EXPECT_NEAR(x.norm(), R, 1e-15 * R);
      const SurfaceValues v = s->at(x, 1.0);
      EXPECT_NEAR(v.H, 1 / R, 1e-14 / R);
      EXPECT_NEAR(v.K, 1 / (R * R), 1e-14 / (R * R));
      EXPECT_NEAR(v.lapH, 0.0, 1e-12 / (R * R * R));
      EXPECT_NEAR(v.f_normal, 0.0, 1e-12 / (R * R * R));
      EXPECT_NEAR((v.normal - x / R).norm(), 0.0, 1e-15);
    }
    const SurfaceMaxima m = s->maxima();
    EXPECT_NEAR(m.H, 1 / R, 1e-14 / R);
    EXPECT_NEAR(m.K, 1 / (R * R), 1e-14 / (R * R));
  }
}

TEST(Sphere, BendingEnergyIsEightPiKb) {
  for (double R : {1e-3, 1.0, 40.0}) {
    const auto owner = make_sphere(R);
    const auto& s = revolution(*owner);
    const double kb = 2.5;
    const double E = 2 * kb * surface_integral(s, [](const MeridianValues& m) { return m.H * m.H; });
    EXPECT_NEAR(E, 8 * kPi * kb, 1e-12 * E);
  }
}

TEST(Spheroid, ClosedFormsAtPolesAndEquator) {
  for (auto [a, c] : {std::pair{1.0, 0.5}, std::pair{0.5, 1.0}, std::pair{2.0, 0.3},
                      std::pair{0.7, 3.0}}) {
    const auto s = make_spheroid(a, c);
    EXPECT_EQ(s->name(), a > c ? "oblate" : "prolate");
    for (double zs : {1.0, -1.0}) {  // poles: c1 = c2 = c / a^2
      const double k = c / (a * a);
      const SurfaceValues v = s->at(Vec3(0, 0, zs * c));
      EXPECT_NEAR(v.H, k, 1e-14 * k);
      EXPECT_NEAR(v.K, k * k, 1e-14 * k * k);
      EXPECT_NEAR(v.normal.z(), zs, 1e-15);
    }
    // Equator: meridional a / c^2, azimuthal 1 / a.
    const double c1 = a / (c * c), c2 = 1 / a;
    const SurfaceValues v = s->at(Vec3(0, a, 0));
    EXPECT_NEAR(v.H, (c1 + c2) / 2, 1e-14 * (c1 + c2));
    EXPECT_NEAR(v.K, c1 * c2, 1e-14 * c1 * c2);
    EXPECT_NEAR((v.normal - Vec3(0, 1, 0)).norm(), 0.0, 1e-15);
    const auto& rev = revolution(*s);
    EXPECT_NEAR(rev.meridian(kPi / 2).c1, c1, 1e-14 * c1);
    EXPECT_NEAR(rev.meridian(kPi / 2).c2, c2, 1e-14 * c2);
    // Gauss-Bonnet holds for every closed surface of genus 0.
    EXPECT_NEAR(surface_integral(rev, [](const MeridianValues& m) { return m.K; }), 4 * kPi, 1e-11);
    // The map lands on x^2/a^2 + y^2/a^2 + z^2/c^2 = 1.
    const Vec3 x = mapped(*s, unit_point(1.0, 2.0));
    EXPECT_NEAR(std::pow(x.x() / a, 2) + std::pow(x.y() / a, 2) + std::pow(x.z() / c, 2), 1.0,
                1e-15);
    EXPECT_NEAR(rev.parameter_of(x), 1.0, 1e-14);
  }
}

TEST(Spheroid, NormalIsTheNormalisedGradientOfTheImplicitForm) {
  const double a = 1.3, c = 0.6;
  const auto s = make_spheroid(a, c);
  for (double t : {0.1, 0.8, 1.9, 3.0}) {
    const Vec3 x = mapped(*s, unit_point(t, -0.4));
    const Vec3 g = Vec3(x.x() / (a * a), x.y() / (a * a), x.z() / (c * c)).normalized();
    EXPECT_NEAR((s->at(x).normal - g).norm(), 0.0, 1e-14);
  }
}

TEST(MakeSurface, ByNameAndErrors) {
  EXPECT_EQ(make_surface("sphere", 2.0)->name(), "sphere");
  EXPECT_EQ(make_surface("rbc")->name(), "rbc");
  EXPECT_EQ(make_surface("oblate")->name(), "oblate");
  EXPECT_EQ(make_surface("prolate")->name(), "prolate");
  EXPECT_EQ(make_surface("spheroid", 1.0, {2.0, 1.0})->name(), "oblate");
  // Defaults: oblate (1, 0.5), prolate (0.5, 1).
  EXPECT_NEAR(make_surface("oblate")->at(Vec3(0, 0, 0.5)).H, 0.5, 1e-15);
  EXPECT_NEAR(make_surface("prolate")->at(Vec3(0, 0, 1.0)).H, 4.0, 1e-14);

  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_THROW(make_surface("torus"), Error);
  EXPECT_THROW(make_surface("Sphere"), Error);
  EXPECT_THROW(make_surface("sphere", -1.0), Error);
  EXPECT_THROW(make_surface("sphere", 0.0), Error);
  EXPECT_THROW(make_surface("sphere", nan), Error);
  EXPECT_THROW(make_surface("rbc", inf), Error);
  EXPECT_THROW(make_surface("rbc", -2.0), Error);
  EXPECT_THROW(make_surface("oblate", 1.0, {0.5, 1.0}), Error);
  EXPECT_THROW(make_surface("oblate", 1.0, {1.0, 1.0}), Error);
  EXPECT_THROW(make_surface("prolate", 1.0, {1.0, 0.5}), Error);
  EXPECT_THROW(make_surface("spheroid"), Error);
  EXPECT_THROW(make_surface("spheroid", 1.0, {1.0}), Error);
  EXPECT_THROW(make_surface("spheroid", 1.0, {1.0, nan}), Error);
  EXPECT_THROW(make_surface("oblate", 1.0, {-1.0, -2.0}), Error);
  EXPECT_THROW(make_spheroid(0.0, 1.0), Error);
  EXPECT_THROW(make_sphere(nan), Error);
}

}  // namespace

TEST(SurfaceOffset, NodesMappedOntoASurfaceLieOnIt) {
  // Random unit-sphere points (both poles and the equator included) mapped onto each surface.
  Points p(203, 3);
  std::mt19937 rng(7);
  std::normal_distribution<double> g;
  for (int i = 0; i < 200; ++i) {
    const Vec3 v(g(rng), g(rng), g(rng));
    p.row(i) = v.normalized().transpose();
  }
  p.row(200) << 0, 0, 1;
  p.row(201) << 0, 0, -1;
  p.row(202) << 1, 0, 0;
  for (const auto& s : {make_sphere(2.5), make_rbc(1.0), make_rbc(3.0), make_surface("oblate"), make_surface("prolate")}) {
    const Points x = s->map_from_unit_sphere(p);
    EXPECT_LT(max_offset(*s, x).max, 1e-14 * s->size()) << s->name();
    EXPECT_NO_THROW(require_nodes_on_surface(*s, x));
  }
}

TEST(SurfaceOffset, MeasuresTheDistanceOffASphereExactly) {
  const auto s = make_sphere(2.0);
  EXPECT_NEAR(s->offset(Vec3(0, 0, 2.5)), 0.5, 1e-15);
  EXPECT_NEAR(s->offset(Vec3(1.2, -1.6, 0)), 0.0, 1e-15);
  EXPECT_NEAR(s->offset(Vec3(0.3, 0.4, 0)), 1.5, 1e-15);
}

TEST(SurfaceOffset, NodesOfAnotherSurfaceAreRefusedNamingTheNode) {
  Points p(3, 3);
  p << 1, 0, 0, 0, 1, 0, 0, 0.6, 0.8;
  const auto sphere = make_sphere(1.0);
  const auto rbc = make_rbc(1.0);
  // Unit-sphere nodes against the RBC: the equator is on both, the third node is not.
  const SurfaceOffset w = max_offset(*rbc, p);
  EXPECT_EQ(w.node, 2);
  EXPECT_GT(w.max, 0.1);
  try {
    require_nodes_on_surface(*rbc, p);
    FAIL() << "expected bendlab::Error";
  } catch (const Error& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("node 2"), std::string::npos) << m;
    EXPECT_NE(m.find("rbc"), std::string::npos) << m;
  }
  EXPECT_NO_THROW(require_nodes_on_surface(*sphere, p));
  // Scaled by 1 + 1e-4: refused at the default tolerance, accepted at a looser one.
  EXPECT_THROW(require_nodes_on_surface(*sphere, 1.0001 * p), Error);
  EXPECT_NO_THROW(require_nodes_on_surface(*sphere, 1.0001 * p, 1e-3));
  Points bad = p;
  bad(1, 2) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(require_nodes_on_surface(*sphere, bad), Error);
}
