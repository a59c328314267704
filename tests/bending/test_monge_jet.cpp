// Method M (Monge jets, ../shared/spec/METHOD_M.md): the graph formulas before any mesh, the fit's
// exactness on polynomial graphs, invariance under rigid motions and scaling, convergence on meshes.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <random>
#include <vector>

#include "bendlab/bending/graph_curvature.hpp"
#include "bendlab/bending/method_registry.hpp"
#include "bendlab/bending/monge_jet.hpp"
#include "bendlab/geometry/mesh_geometry.hpp"
#include "bendlab/mesh/generators.hpp"
#include "bendlab/surfaces/analytic_surface.hpp"
#include "bending/shape_test_support.hpp"

using namespace bendlab;
using test_support::some_rotation;

namespace {

constexpr int kOrder = 4;

/// A function of (u, v) as its Taylor polynomial to total degree 4 about a point:
/// c[a][b] is the coefficient of u^a v^b. Just enough arithmetic for the sphere's height function.
struct Series {
  std::array<std::array<double, kOrder + 1>, kOrder + 1> c{};
  Series operator*(const Series& o) const {
    Series r;
    for (int a = 0; a <= kOrder; ++a)
      for (int b = 0; a + b <= kOrder; ++b)
        for (int i = 0; i <= a; ++i)
          for (int j = 0; j <= b; ++j) r.c[a][b] += c[i][j] * o.c[a - i][b - j];
    return r;
  }
  /// sqrt by matching coefficients of s^2 = *this, degree by degree (c[0][0] > 0).
  Series sqrt() const {
    Series s;
    s.c[0][0] = std::sqrt(c[0][0]);
    for (int k = 1; k <= kOrder; ++k)
      for (int a = 0; a <= k; ++a) {
        const int b = k - a;
        double rest = c[a][b];
        for (int i = 0; i <= a; ++i)
          for (int j = 0; j <= b; ++j)
            if (!(i == 0 && j == 0) && !(i == a && j == b)) rest -= s.c[i][j] * s.c[a - i][b - j];
        s.c[a][b] = rest / (2 * s.c[0][0]);
      }
    return s;
  }
  /// d^(a+b) / du^a dv^b at the point: a! b! c_ab.
  double derivative(int a, int b) const {
    double f = c[a][b];
    for (int k = 2; k <= a; ++k) f *= k;
    for (int k = 2; k <= b; ++k) f *= k;
    return f;
  }
};

HeightDerivatives derivatives_of(const Series& h) {
  HeightDerivatives d;
  d.u = h.derivative(1, 0), d.v = h.derivative(0, 1);
  d.uu = h.derivative(2, 0), d.uv = h.derivative(1, 1), d.vv = h.derivative(0, 2);
  d.uuu = h.derivative(3, 0), d.uuv = h.derivative(2, 1), d.uvv = h.derivative(1, 2), d.vvv = h.derivative(0, 3);
  d.uuuu = h.derivative(4, 0), d.uuuv = h.derivative(3, 1), d.uuvv = h.derivative(2, 2);
  d.uvvv = h.derivative(1, 3), d.vvvv = h.derivative(0, 4);
  return d;
}

/// A generic polynomial graph z = P(x, y) of degree 5 with random coefficients, placed in space by a
/// rotation q and an origin o.
struct PolynomialGraph {
  std::array<std::array<double, 6>, 6> c{};  ///< coefficient of x^a y^b, a + b <= 5
  Mat3 q = some_rotation();
  Vec3 o = Vec3(0.3, -1.2, 2.5);

  explicit PolynomialGraph(unsigned seed, int degree = 5) {
    std::mt19937 gen(seed);
    std::uniform_real_distribution<double> coef(-1, 1);
    for (int a = 0; a <= degree; ++a)
      for (int b = 0; a + b <= degree; ++b) c[a][b] = coef(gen);
  }
  /// d^(i+j) P / dx^i dy^j at (x, y).
  double d(int i, int j, double x, double y) const {
    double s = 0;
    for (int a = i; a <= 5; ++a)
      for (int b = j; a + b <= 5; ++b) {
        double f = c[a][b];
        for (int k = 0; k < i; ++k) f *= a - k;
        for (int k = 0; k < j; ++k) f *= b - k;
        s += f * std::pow(x, a - i) * std::pow(y, b - j);
      }
    return s;
  }
  Vec3 point(double x, double y) const { return o + q * Vec3(x, y, d(0, 0, x, y)); }
  double w2(double x, double y) const { return 1 + std::pow(d(1, 0, x, y), 2) + std::pow(d(0, 1, x, y), 2); }
  /// Textbook Monge-patch mean curvature, positive where the graph bends away from +z.
  double H(double x, double y) const {
    const double p = d(1, 0, x, y), q_ = d(0, 1, x, y), r = d(2, 0, x, y), s = d(1, 1, x, y), t = d(0, 2, x, y);
    return -((1 + q_ * q_) * r - 2 * p * q_ * s + (1 + p * p) * t) / (2 * std::pow(w2(x, y), 1.5));
  }
  double K(double x, double y) const {
    return (d(2, 0, x, y) * d(0, 2, x, y) - std::pow(d(1, 1, x, y), 2)) / std::pow(w2(x, y), 2);
  }
  Vec3 normal(double x, double y) const { return q * Vec3(-d(1, 0, x, y), -d(0, 1, x, y), 1) / std::sqrt(w2(x, y)); }
  /// Lap_S H in divergence form, (1/sqrt g) d_a (sqrt g g^ab d_b H), by nested fourth-order central
  /// differences: a computation that shares nothing with the jet arithmetic of the method.
  double lap_divergence_form(double x, double y) const {
    const double e = 1e-3;
    auto d1 = [e](const std::function<double(double)>& f) {
      return (f(-2 * e) - 8 * f(-e) + 8 * f(e) - f(2 * e)) / (12 * e);
    };
    auto grad_H = [&](double px, double py) {
      return Eigen::Vector2d(d1([&](double t) { return H(px + t, py); }), d1([&](double t) { return H(px, py + t); }));
    };
    auto flux = [&](double px, double py) {  // sqrt g g^ab d_b H, g^ab = delta - h_a h_b / W^2
      const Eigen::Vector2d gh(d(1, 0, px, py), d(0, 1, px, py));
      const double w2_ = 1 + gh.squaredNorm();
      const Eigen::Matrix2d g_inv = Eigen::Matrix2d::Identity() - gh * gh.transpose() / w2_;
      return Eigen::Vector2d(std::sqrt(w2_) * g_inv * grad_H(px, py));
    };
    const double div = d1([&](double t) { return flux(x + t, y)[0]; }) + d1([&](double t) { return flux(x, y + t)[1]; });
    return div / std::sqrt(w2(x, y));
  }
};

/// Points of the graph around (x0, y0) in a disc of radius r (the node itself excluded).
std::vector<Vec3> graph_support(const PolynomialGraph& g, double x0, double y0, int count, double r, unsigned seed) {
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> ang(0, 2 * M_PI), rad(0.2 * r, r);
  std::vector<Vec3> p;
  for (int k = 0; k < count; ++k) {
    const double t = ang(gen), s = rad(gen);
    p.push_back(g.point(x0 + s * std::cos(t), y0 + s * std::sin(t)));
  }
  return p;
}

BendingResult method_m(const Points& x, const Topology& t, const MethodOptions& options = {}) {
  return make_bending_method("M", options)->compute(t, x, 1.0);
}

/// Max error of f over the nodes relative to max|f| (eq. (17)) of Method M on the RBC.
double rbc_max_error_f(const TriMesh& sphere, const Mat3& rotation, const MethodOptions& options) {
  const auto rbc = make_rbc();
  Points on_sphere = sphere.positions() * rotation.transpose();
  const Points x = rbc->map_from_unit_sphere(on_sphere);
  const SurfaceFields exact = rbc->evaluate(x);
  const BendingResult r = method_m(x, sphere.topology(), options);
  double e = 0;
  for (Eigen::Index i = 0; i < x.rows(); ++i) e = std::max(e, (exact.f.row(i) - r.force_density.row(i)).norm());
  return e / rbc->maxima().f;
}

}  // namespace

TEST(GraphCurvature, SphereInATiltedFrameIsExact) {
  // The sphere |x| = R as the graph z = sqrt(R^2 - x^2 - y^2), seen at points away from the pole,
  // where the chart (e_x, e_y, e_z) is tilted against the tangent plane.
  for (const double radius : {1.0, 2.5}) {
    for (const auto& [x0, y0] : {std::pair{0.3, -0.5}, std::pair{-0.7, 0.2}, std::pair{0.1, 0.85}}) {
      const double px = x0 * radius, py = y0 * radius;
      Series a;  // R^2 - (px + u)^2 - (py + v)^2
      a.c[0][0] = radius * radius - px * px - py * py;
      a.c[1][0] = -2 * px, a.c[0][1] = -2 * py, a.c[2][0] = a.c[0][2] = -1;
      const Series h = a.sqrt();
      const GraphCurvatures g = graph_curvatures(derivatives_of(h));
      EXPECT_NEAR(g.H, 1 / radius, 1e-14 / radius);
      EXPECT_NEAR(g.K, 1 / (radius * radius), 1e-14 / (radius * radius));
      EXPECT_NEAR(g.lapH, 0.0, 1e-13 / std::pow(radius, 3));
      EXPECT_NEAR((g.normal_local - Vec3(px, py, h.c[0][0]) / radius).norm(), 0.0, 1e-14);
    }
  }
}

TEST(GraphCurvature, JetArithmeticFollowsLeibnizAndChainRules) {
  // f = 1 + u + 2v + 3u^2 + uv (jet at 0), g = 2 - v + u^2: (f g) and f^-1.5 against hand values.
  const SecondOrderJet f{1, 1, 2, 6, 1, 0}, g{2, 0, -1, 2, 0, 0};
  const SecondOrderJet fg = f * g;
  EXPECT_DOUBLE_EQ(fg.f, 2);
  EXPECT_DOUBLE_EQ(fg.u, 2);                        // f_u g + f g_u
  EXPECT_DOUBLE_EQ(fg.v, 4 - 1);                    // f_v g + f g_v
  EXPECT_DOUBLE_EQ(fg.uu, 6 * 2 + 0 + 1 * 2);       // f_uu g + 2 f_u g_u + f g_uu
  EXPECT_DOUBLE_EQ(fg.uv, 1 * 2 + 1 * -1 + 2 * 0);  // f_uv g + f_u g_v + f_v g_u + f g_uv
  EXPECT_DOUBLE_EQ(fg.vv, 0 + 2 * 2 * -1 + 0);
  const SecondOrderJet p = pow(f, -1.5);
  EXPECT_DOUBLE_EQ(p.u, -1.5);
  EXPECT_DOUBLE_EQ(p.uv, 3.75 * 1 * 2 - 1.5 * 1);
}

TEST(MongeJetFit, ExactOnPolynomialGraphsOfDegreeAtMostFive) {
  // At any node (x0, y0) the height above the plane of n0 = q e_z is a polynomial of degree <= 5 in
  // the chart coordinates, so the degree-5 fit is exact and n, H, K, Lap_S H are the graph's own;
  // Lap_S H is compared with its divergence form evaluated at (x0, y0), away from the origin.
  for (const unsigned seed : {1u, 2u, 3u}) {
    for (const int degree : {3, 5}) {
      const PolynomialGraph g(seed, degree);
      for (const auto& [x0, y0] : {std::pair{0.0, 0.0}, std::pair{0.23, -0.17}, std::pair{-0.4, 0.31}}) {
        const std::vector<Vec3> support = graph_support(g, x0, y0, 36, 0.15, seed + 7);
        const MongeJetFit fit = monge_jet_fit_point(g.point(x0, y0), g.q.col(2), support, 5);
        ASSERT_TRUE(fit.valid);
        const double lap = g.lap_divergence_form(x0, y0);
        const double scale = 1 + std::abs(lap);
        EXPECT_NEAR(fit.H, g.H(x0, y0), 1e-9) << seed << " " << x0;
        EXPECT_NEAR(fit.K, g.K(x0, y0), 1e-9) << seed << " " << x0;
        EXPECT_NEAR((fit.normal - g.normal(x0, y0)).norm(), 0.0, 1e-10);
        EXPECT_NEAR(fit.lapH, lap, 2e-7 * scale) << seed << " " << x0;
      }
    }
  }
}

TEST(MongeJetFit, DegreeSixIsExactOnDegreeFiveAndDegreeFourIsNot) {
  const PolynomialGraph g(4);
  const std::vector<Vec3> support = graph_support(g, 0.1, 0.2, 40, 0.15, 9);
  const MongeJetFit six = monge_jet_fit_point(g.point(0.1, 0.2), g.q.col(2), support, 6);
  const MongeJetFit four = monge_jet_fit_point(g.point(0.1, 0.2), g.q.col(2), support, 4);
  ASSERT_TRUE(six.valid && four.valid);
  EXPECT_NEAR(six.H, g.H(0.1, 0.2), 1e-8);
  EXPECT_NEAR(six.lapH, g.lap_divergence_form(0.1, 0.2), 1e-5 * (1 + std::abs(six.lapH)));
  EXPECT_GT(std::abs(four.lapH - g.lap_divergence_form(0.1, 0.2)), 1e-4);
}

TEST(MongeJetFit, MomentSumsEqualTheOuterProductReference) {
  // The fast path (normal matrix from the support's moments) against the plain sum of outer products,
  // on a support off any polynomial, every degree, with and without weights.
  std::mt19937 gen(21);
  std::normal_distribution<double> noise(0, 2e-3);
  const PolynomialGraph g(6);
  std::vector<Vec3> support = graph_support(g, 0.05, -0.1, 36, 0.15, 4);
  for (Vec3& p : support) p += Vec3(noise(gen), noise(gen), noise(gen));
  const Vec3 x0 = g.point(0.05, -0.1), n0 = (g.q * Vec3(0.05, 0.02, 1)).normalized();
  for (const int degree : {4, 5, 6})
    for (const bool weights : {false, true}) {
      const MongeJetFit fast = monge_jet_fit_point(x0, n0, support, degree, weights, Accumulation::Moments);
      const MongeJetFit ref = monge_jet_fit_point(x0, n0, support, degree, weights, Accumulation::OuterProducts);
      ASSERT_TRUE(fast.valid && ref.valid);
      EXPECT_NEAR(fast.H, ref.H, 1e-10 * std::abs(ref.H)) << degree;
      EXPECT_NEAR(fast.K, ref.K, 1e-9 * std::abs(ref.K)) << degree;
      EXPECT_NEAR(fast.lapH, ref.lapH, 1e-8 * (1 + std::abs(ref.lapH))) << degree;
      EXPECT_NEAR((fast.normal - ref.normal).norm(), 0.0, 1e-12) << degree;
    }
}

TEST(MongeJetFit, TooFewOrDegeneratePointsAreInvalid) {
  const PolynomialGraph g(5);
  const std::vector<Vec3> few = graph_support(g, 0, 0, 19, 0.15, 3);  // 20 unknowns
  const MongeJetFit f = monge_jet_fit_point(g.point(0, 0), g.q.col(2), few, 5);
  EXPECT_FALSE(f.valid);
  EXPECT_TRUE(std::isnan(f.H) && std::isnan(f.lapH) && std::isnan(f.normal.x()));
  // 30 points on two lines through the node: the jet's mixed terms are free.
  std::vector<Vec3> lines;
  for (int k = 1; k <= 15; ++k) lines.push_back(g.point(0.01 * k, 0)), lines.push_back(g.point(0, -0.01 * k));
  EXPECT_FALSE(monge_jet_fit_point(g.point(0, 0), g.q.col(2), lines, 5).valid);
}

TEST(MongeJetFit, LanesEqualTheOneNodeReference) {
  // monge_jet_fit_nodes (8 nodes side by side in SIMD lanes, the method's path) against
  // monge_jet_fit_point one node at a time: 19 nodes (two full batches and a partial one) with
  // supports of different sizes and noise, one with too few points and one degenerate (points on
  // two lines) among them, every degree, with and without weights.
  std::mt19937 gen(5);
  std::normal_distribution<double> noise(0, 1e-3);
  const PolynomialGraph g(6);
  std::vector<std::vector<Vec3>> supports;
  std::vector<MongeJetNode> nodes;
  for (int k = 0; k < 19; ++k) {
    const double u0 = 0.01 * k - 0.09, v0 = 0.05 - 0.007 * k;
    std::vector<Vec3> support;
    if (k == 4) {
      support = graph_support(g, u0, v0, 12, 0.15, 3);  // fewer points than unknowns
    } else if (k == 11) {
      for (int j = 1; j <= 18; ++j) support.push_back(g.point(u0 + 0.01 * j, v0)), support.push_back(g.point(u0, v0 - 0.01 * j));
    } else {
      support = graph_support(g, u0, v0, 30 + k % 9, 0.15, 4);
      for (Vec3& q : support) q += Vec3(noise(gen), noise(gen), noise(gen));
    }
    supports.push_back(std::move(support));
  }
  for (int k = 0; k < 19; ++k) {
    const double u0 = 0.01 * k - 0.09, v0 = 0.05 - 0.007 * k;
    nodes.push_back(MongeJetNode{g.point(u0, v0), (g.q * Vec3(0.03 * k - 0.2, 0.02, 1)).normalized(), supports[k]});
  }
  for (const int degree : {4, 5, 6})
    for (const bool weights : {false, true}) {
      const std::vector<MongeJetFit> lanes = monge_jet_fit_nodes(nodes, degree, weights);
      ASSERT_EQ(lanes.size(), nodes.size());
      for (int k = 0; k < 19; ++k) {
        const MongeJetFit ref = monge_jet_fit_point(nodes[k].x0, nodes[k].n0, nodes[k].support, degree, weights);
        const MongeJetFit& fit = lanes[k];
        ASSERT_EQ(fit.valid, ref.valid) << "node " << k << ", degree " << degree;
        EXPECT_EQ(fit.points, ref.points);
        if (k == 4 || k == 11) EXPECT_FALSE(fit.valid) << k;
        if (!ref.valid) {
          EXPECT_TRUE(std::isnan(fit.H) && std::isnan(fit.lapH) && std::isnan(fit.normal.x())) << k;
          continue;
        }
        // Two backward-stable solves of the same normal equations differ by round-off times the
        // normal matrix's condition number: the spec's design matrices have 5e2-4e3, so up to
        // 2e7 for M = Phi^T Phi, i.e. about 4e-9 relative in the coefficients.
        EXPECT_NEAR(fit.scale, ref.scale, 1e-15 * ref.scale);
        EXPECT_NEAR(fit.H, ref.H, 1e-8 * std::abs(ref.H)) << k << " " << degree;
        EXPECT_NEAR(fit.K, ref.K, 1e-8 * std::abs(ref.K)) << k << " " << degree;
        EXPECT_NEAR(fit.lapH, ref.lapH, 1e-7 * (1 + std::abs(ref.lapH))) << k << " " << degree;
        EXPECT_NEAR((fit.normal - ref.normal).norm(), 0.0, 1e-9) << k << " " << degree;
      }
    }
  EXPECT_TRUE(monge_jet_fit_nodes({}, 6).empty());
  EXPECT_THROW(monge_jet_fit_nodes(nodes, 7), Error);
}

TEST(MongeJet, RegistryEntryAndOptions) {
  const MethodInfo& info = bending_method_info("M");
  EXPECT_FALSE(info.capabilities.has_energy);
  EXPECT_TRUE(info.capabilities.defines_lapH);
  EXPECT_EQ(make_bending_method("M")->name(), "M");
  const auto defaults = make_bending_method("M");
  const MongeJetSettings& s = dynamic_cast<const MongeJetMethod&>(*defaults).settings();
  EXPECT_EQ(s.degree, 6);
  EXPECT_EQ(s.rings, 3);
  EXPECT_EQ(s.frame, MongeFrame::Covariance);
  EXPECT_FALSE(s.gaussian_weights);
  const auto chosen = make_bending_method(
      "M", {{"degree", "5"}, {"support_rings", "2"}, {"frame", "angle-weighted"}, {"gaussian_weights", "true"}});
  const MongeJetSettings& t = dynamic_cast<const MongeJetMethod&>(*chosen).settings();
  EXPECT_EQ(t.degree, 5);
  EXPECT_EQ(t.rings, 2);
  EXPECT_EQ(t.frame, MongeFrame::AngleWeighted);
  EXPECT_TRUE(t.gaussian_weights);
  EXPECT_EQ(s.laplacian, MongeLaplacian::Field);
  EXPECT_EQ(s.support_points, 0);
  EXPECT_EQ(dynamic_cast<const MongeJetMethod&>(*make_bending_method("M", {{"laplacian", "jet"}})).settings().laplacian,
            MongeLaplacian::Jet);
  for (const auto& [key, bad] : {std::pair{"degree", "3"}, std::pair{"degree", "7"}, std::pair{"support_rings", "1"},
                                 std::pair{"support_rings", "4"}, std::pair{"frame", "mwa"}, std::pair{"degree", ""},
                                 std::pair{"laplacian", "cotangent"}})
    EXPECT_THROW(make_bending_method("M", {{key, bad}}), Error) << key << "=" << bad;
}

TEST(MongeJet, RefusesAMeshTooSmallForTheJetNamingTheVertex) {
  const TriMesh ico = icosahedron();  // 11 other vertices, 27 unknowns (degree 6)
  try {
    method_m(ico.positions(), ico.topology());
    FAIL() << "no error";
  } catch (const Error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("method M"), std::string::npos) << what;
    EXPECT_NE(what.find("vertex 0"), std::string::npos) << what;
    EXPECT_NE(what.find("27 unknowns"), std::string::npos) << what;
  }
  // Degree 4 (14 unknowns) still needs 14 points: refused too, at 11.
  EXPECT_THROW(method_m(ico.positions(), ico.topology(), {{"degree", "4"}}), Error);
}

TEST(MongeJet, RigidMotionsAndScalingActAsTheyMust) {
  // n turns with the mesh; H, K, Lap H and f . n are invariant under rigid motions; under x -> l x,
  // H -> H / l, K -> K / l^2, Lap H -> Lap H / l^3, f -> f / l^3 (eq. (10)).
  const TriMesh m = sphere_mesh(MeshFamily::MT1, 3);
  const Points x = make_rbc()->map_from_unit_sphere(m.positions());
  const Mat3 q = some_rotation();
  const Vec3 b(0.4, -2.0, 7.5);
  const double l = 3.7;
  const Points moved = (x * q.transpose()).rowwise() + b.transpose();
  const Points scaled = l * x;
  const BendingResult r0 = method_m(x, m.topology()), r1 = method_m(moved, m.topology()),
                      r2 = method_m(scaled, m.topology());
  const double fmax = r0.force_density.rowwise().norm().maxCoeff();
  const double hmax = r0.H.cwiseAbs().maxCoeff(), kmax = r0.K.cwiseAbs().maxCoeff(),
               lmax = r0.lapH.cwiseAbs().maxCoeff();
  for (Eigen::Index i = 0; i < x.rows(); ++i) {
    EXPECT_NEAR((q * row(r0.normal, i) - row(r1.normal, i)).norm(), 0.0, 1e-9);
    EXPECT_NEAR((row(r0.normal, i) - row(r2.normal, i)).norm(), 0.0, 1e-9);
    EXPECT_NEAR(r1.H[i], r0.H[i], 1e-9 * hmax);
    EXPECT_NEAR(r2.H[i] * l, r0.H[i], 1e-9 * hmax);
    EXPECT_NEAR(r1.K[i], r0.K[i], 1e-9 * kmax);
    EXPECT_NEAR(r2.K[i] * l * l, r0.K[i], 1e-9 * kmax);
    EXPECT_NEAR(r1.lapH[i], r0.lapH[i], 1e-8 * lmax);
    EXPECT_NEAR(r2.lapH[i] * l * l * l, r0.lapH[i], 1e-8 * lmax);
    EXPECT_NEAR((q * row(r0.force_density, i) - row(r1.force_density, i)).norm(), 0.0, 1e-8 * fmax);
    EXPECT_NEAR((row(r0.force_density, i) - l * l * l * row(r2.force_density, i)).norm(), 0.0, 1e-8 * fmax);
  }
}

TEST(MongeJet, KeptSupportsFollowTheConnectivity) {
  // The method keeps each connectivity's supports: one method object on two meshes in turn (and
  // on a mesh with the same vertex count but other faces) gives what fresh objects give, and
  // supports built for one connectivity are refused for another.
  const TriMesh a = sphere_mesh(MeshFamily::MT1, 2), b = sphere_mesh(MeshFamily::MT2, 2);
  std::vector<Eigen::Vector3i> flipped;  // a's faces in another order and rotation: other faces, same surface
  for (Eigen::Index f = a.topology().faces().rows() - 1; f >= 0; --f) {
    const auto& row_f = a.topology().faces().row(f);
    flipped.emplace_back(row_f[1], row_f[2], row_f[0]);
  }
  Faces faces(static_cast<Eigen::Index>(flipped.size()), 3);
  for (std::size_t f = 0; f < flipped.size(); ++f) faces.row(static_cast<Eigen::Index>(f)) = flipped[f].transpose();
  const TriMesh c(a.positions(), faces);
  const auto kept = make_bending_method("M");
  for (const TriMesh* m : {&a, &b, &a, &c, &b}) {
    const BendingResult r = kept->compute(m->topology(), m->positions(), 1.0);
    const BendingResult fresh = make_bending_method("M")->compute(m->topology(), m->positions(), 1.0);
    EXPECT_EQ(r.force, fresh.force);
    EXPECT_EQ(r.H, fresh.H);
  }
  const MongeJetSettings settings;
  const MongeJetSupports supports = MongeJetSupports::build(a.topology(), settings);
  EXPECT_TRUE(supports.matches(a.topology(), settings));
  EXPECT_FALSE(supports.matches(c.topology(), settings));
  MongeJetSettings two_rings = settings;
  two_rings.rings = 2;
  EXPECT_FALSE(supports.matches(a.topology(), two_rings));
  const MeshGeometry g = MeshGeometry::compute(c.topology(), c.positions());
  EXPECT_THROW(monge_jet_fit(c.topology(), c.positions(), g.normal_mwa, settings, supports), Error);
}

TEST(MongeJet, SupportTrimKeepsRegularThreeRingsWhole) {
  // The trim to the 40 nearest points (and those as near) leaves a valence-6 vertex's 3-ring of
  // 36 points whole, so away from the 12 valence-5 vertices and their neighbourhoods M's H equals
  // the untrimmed method's to the last bit; the valence-5 vertices, whose supports were widened to
  // 4 rings, are trimmed and change. Counts below unknowns + 4 are refused.
  const TriMesh sphere = sphere_mesh(MeshFamily::MT1, 3);  // 1280 triangles
  const TriMesh m = sphere.with_positions(make_rbc()->map_from_unit_sphere(sphere.positions()));
  const BendingResult trimmed =
      make_bending_method("M", {{"support_points", "40"}})->compute(m.topology(), m.positions(), 1.0);
  const BendingResult whole =
      make_bending_method("M", {{"support_points", "0"}})->compute(m.topology(), m.positions(), 1.0);
  int same = 0, changed_irregular = 0;
  for (int i = 0; i < m.num_vertices(); ++i) {
    if (m.topology().valence(i) == 6) same += trimmed.H[i] == whole.H[i];
    else changed_irregular += trimmed.H[i] != whole.H[i];
  }
  int valence6 = 0;
  for (int i = 0; i < m.num_vertices(); ++i) valence6 += m.topology().valence(i) == 6;
  EXPECT_EQ(same, valence6);
  EXPECT_EQ(changed_irregular, 12);
  EXPECT_THROW(make_bending_method("M", {{"support_points", "30"}}), Error);
  EXPECT_THROW(make_bending_method("M", {{"support_points", "23"}, {"degree", "5"}}), Error);
  EXPECT_NO_THROW(make_bending_method("M", {{"support_points", "24"}, {"degree", "5"}}));
}

TEST(MongeJet, SphereMeshesConvergeToTheSphere) {
  // On the unit sphere H = 1, K = 1, Lap H = 0 and f = 0: the errors fall under refinement.
  std::array<double, 4> previous{INFINITY, INFINITY, INFINITY, INFINITY};
  for (int level = 3; level <= 5; ++level) {
    const TriMesh m = sphere_mesh(MeshFamily::MT2, level);
    const BendingResult r = method_m(m.positions(), m.topology());
    double eh = 0, ek = 0, el = 0, en = 0;
    for (Eigen::Index i = 0; i < m.positions().rows(); ++i) {
      eh = std::max(eh, std::abs(r.H[i] - 1));
      ek = std::max(ek, std::abs(r.K[i] - 1));
      el = std::max(el, std::abs(r.lapH[i]));
      en = std::max(en, (row(r.normal, i) - row(m.positions(), i)).norm());
    }
    std::printf("M unit sphere MT2 level %d: max |H-1| %.2e |K-1| %.2e |Lap H| %.2e |n-x| %.2e\n", level, eh, ek,
                el, en);
    // Each refinement halves h: second order or better divides the errors by about 4.
    EXPECT_LT(el, 0.4 * previous[0]) << "level " << level;
    EXPECT_LT(eh, 0.4 * previous[1]) << "level " << level;
    EXPECT_LT(ek, 0.4 * previous[2]) << "level " << level;
    EXPECT_LT(en, 0.4 * previous[3]) << "level " << level;
    previous = {el, eh, ek, en};
  }
}

TEST(MongeJetLaplacian, DegreeOneSphericalHarmonicConverges) {
  // On the unit sphere Lap_S z = -2 z (z is a spherical harmonic of degree 1): the jets' operator
  // applied to the field z converges to it, at second order or better, with every degree.
  for (int degree : {4, 5, 6}) {
    MongeJetSettings settings;
    settings.degree = degree;
    double previous = INFINITY;
    for (int level = 3; level <= 5; ++level) {
      const TriMesh m = sphere_mesh(MeshFamily::MT2, level);
      const MeshGeometry g = MeshGeometry::compute(m.topology(), m.positions());
      const MongeJetSupports supports = MongeJetSupports::build(m.topology(), settings);
      const std::vector<MongeJetFit> fits = monge_jet_fit(m.topology(), m.positions(), g.normal_mwa, settings, supports);
      const Scalars z = m.positions().col(2);
      Scalars lap;
      monge_jet_laplacian(m.topology(), m.positions(), settings, supports, fits, z, lap);
      const double err = (lap + 2 * z).cwiseAbs().maxCoeff();
      EXPECT_LT(err, 0.4 * previous) << "degree " << degree << " level " << level;
      previous = err;
    }
    EXPECT_LT(previous, 1e-3) << "degree " << degree;
  }
}

TEST(MongeJetLaplacian, StencilFromTheFitsEqualsTheReference) {
  // The fast path (the stencil's weights from the fits' own factors, solve_jet_lanes) against the
  // reference (monge_jet_laplacian: each node's normal matrix summed and factored again): the same
  // operator up to round-off, for every degree, with and without the trim and the Gaussian weights,
  // on the RBC of the irregular family (jittered: no two supports alike).
  const TriMesh sphere = sphere_mesh(MeshFamily::Irregular, 3);
  const TriMesh m = sphere.with_positions(make_rbc()->map_from_unit_sphere(sphere.positions()));
  const MeshGeometry g = MeshGeometry::compute(m.topology(), m.positions());
  const Scalars w = m.positions().col(0).array() * m.positions().col(2).array() + m.positions().col(1).array();
  for (int degree : {4, 5, 6})
    for (int trim : {0, 40})
      for (bool gaussian : {false, true}) {
        MongeJetSettings settings;
        settings.degree = degree;
        settings.support_points = trim;
        settings.gaussian_weights = gaussian;
        const MongeJetSupports supports = MongeJetSupports::build(m.topology(), settings);
        MongeJetWorkspace ws;
        std::vector<MongeJetFit> fits;
        MongeJetLaplacianStencil stencil;
        monge_jet_fit(m.topology(), m.positions(), g.normal_mwa, settings, supports, ws, fits, &stencil);
        Scalars fast, reference;
        stencil.apply(w, fast);
        monge_jet_laplacian(m.topology(), m.positions(), settings, supports, fits, w, reference);
        const double scale = reference.cwiseAbs().maxCoeff();
        EXPECT_LT((fast - reference).cwiseAbs().maxCoeff(), 1e-9 * scale)
            << "degree " << degree << " trim " << trim << " gaussian " << gaussian;
        // The fits themselves are those without the stencil, bit for bit.
        std::vector<MongeJetFit> plain;
        monge_jet_fit(m.topology(), m.positions(), g.normal_mwa, settings, supports, ws, plain);
        for (int i = 0; i < m.num_vertices(); ++i) ASSERT_EQ(plain[i].H, fits[i].H) << i;
      }
}

TEST(MongeJetLaplacian, FieldLaplacianOfHConvergesOnTheSphere) {
  // laplacian=field: Lap H is the jets' operator applied to H, which is 1 on the unit sphere up to
  // the fits' error: Lap H and f fall under refinement.
  double previous = INFINITY;
  for (int level = 3; level <= 5; ++level) {
    const TriMesh m = sphere_mesh(MeshFamily::MT2, level);
    const BendingResult r = make_bending_method("M", {{"laplacian", "field"}})->compute(m.topology(), m.positions(), 1.0);
    const double el = r.lapH.cwiseAbs().maxCoeff();
    EXPECT_LT(el, 0.4 * previous) << "level " << level;
    previous = el;
  }
}

// The acceptance: the maximum error of f on the RBC converges with slope <= -1.5 over the
// three finest meshes up to 81920 triangles, below 2e-2 of max|f| at the finest, on MT1, MT2, the
// octahedron family (levels 5-7: 8192, 32768 and 131072 triangles) and the irregular family (jittered
// afresh at every level), also on randomly rotated meshes.
TEST(MongeJet, RbcMaximumErrorOfFConvergesAtSecondOrder) {
#if defined(__SANITIZE_ADDRESS__)
  GTEST_SKIP() << "81920 triangles: too slow under the sanitizers";
#else
  const Mat3 random_rotation =
      Eigen::Quaterniond(Eigen::Vector4d(0.31, -0.72, 0.45, 0.43).normalized()).toRotationMatrix();
  struct Case {
    MeshFamily family;
    int first_level;
    Mat3 rotation;
    MethodOptions options;
  };
  std::vector<Case> cases;
  // The defaults (degree 6, Lap H from the jets' operator applied to H, whole rings), the spec's
  // degree 5, and the former defaults (Lap H from the jet's own derivatives, the 40-point trim).
  for (const MethodOptions& options : {MethodOptions{}, MethodOptions{{"degree", "5"}, {"laplacian", "jet"}},
                                       MethodOptions{{"laplacian", "jet"}, {"support_points", "40"}}})
    for (const Case& c : {Case{MeshFamily::MT1, 4, Mat3::Identity(), options},
                          Case{MeshFamily::MT2, 4, Mat3::Identity(), options},
                          Case{MeshFamily::Octa, 5, Mat3::Identity(), options},
                          Case{MeshFamily::Irregular, 4, Mat3::Identity(), options},
                          Case{MeshFamily::MT1, 4, random_rotation, options},
                          Case{MeshFamily::Irregular, 4, random_rotation, options}})
      cases.push_back(c);
  for (const Case& c : cases) {
    std::vector<double> err, h;
    for (int level = c.first_level; level < c.first_level + 3; ++level) {
      const TriMesh m = sphere_mesh(c.family, level);
      err.push_back(rbc_max_error_f(m, c.rotation, c.options));
      h.push_back(1.0 / std::sqrt(double(m.num_faces())));
    }
    // Least-squares slope of log(err) against log(1/h).
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    for (std::size_t k = 0; k < err.size(); ++k) {
      const double lx = -std::log(h[k]), ly = std::log(err[k]);
      sx += lx, sy += ly, sxx += lx * lx, sxy += lx * ly;
    }
    const double n = static_cast<double>(err.size());
    const double slope = (n * sxy - sx * sy) / (n * sxx - sx * sx);
    std::string label;
    for (const auto& [key, value] : c.options) label += key + "=" + value;
    std::printf("M (%s) max err f, %s: %.3e %.3e %.3e, slope %.2f\n", label.empty() ? "defaults" : label.c_str(),
                to_string(c.family).c_str(), err[0], err[1], err[2], slope);
    EXPECT_LE(slope, -1.5) << to_string(c.family);
    EXPECT_LT(err.back(), 2e-2) << to_string(c.family);
  }
#endif
}

TEST(MongeJet, ASupportOnThreeLinesFallsBackToDegreeTwo) {
  // 36 points on three lines through the node in the tangent plane, on the paraboloid
  // h = 0.1 u^2 + 0.3 v^2: the cubic that is the product of the three lines vanishes on all of them,
  // so the jets of degree 6 and 4 (which contain it times any polynomial of degree 3 or 1) are not
  // determined; degree 2 is, and is exact on the paraboloid: H = (h_uu + h_vv) / 2 = 0.4 up to sign.
  const Vec3 x0(0.2, -0.1, 0.4), n0 = Vec3(0.3, 0.2, 1.0).normalized();
  const Vec3 t1 = n0.unitOrthogonal(), t2 = n0.cross(t1);
  std::vector<Vec3> support;
  for (int line = 0; line < 3; ++line)
    for (int k = 1; k <= 12; ++k) {
      const double angle = 0.4 + line * 1.1, r = (k % 2 ? 1.0 : -1.0) * 0.05 * ((k + 1) / 2);
      const double u = r * std::cos(angle), v = r * std::sin(angle);
      support.push_back(x0 + u * t1 + v * t2 + (0.1 * u * u + 0.3 * v * v) * n0);
    }
  MongeJetSettings settings;
  EXPECT_FALSE(monge_jet_fit_point(x0, n0, support, 6).valid);
  EXPECT_FALSE(monge_jet_fit_point(x0, n0, support, 4).valid);
  const MongeJetFit fit = monge_jet_fallback_fit(x0, n0, support, settings);
  ASSERT_TRUE(fit.valid);
  EXPECT_EQ(fit.degree, 2);
  EXPECT_NEAR(std::abs(fit.H), 0.4, 1e-9);
  EXPECT_NEAR(fit.K, 4 * 0.1 * 0.3, 1e-9);
  EXPECT_NEAR(std::abs(fit.normal.dot(n0)), 1.0, 1e-12);
  // On a support that determines the degree-6 jet nothing falls back.
  std::vector<Vec3> spread;
  for (int k = 0; k < 40; ++k) {
    const double u = 0.3 * std::cos(2.4 * k) * std::sqrt((k + 1) / 40.0), v = 0.3 * std::sin(2.4 * k) * std::sqrt((k + 1) / 40.0);
    spread.push_back(x0 + u * t1 + v * t2 + (0.1 * u * u + 0.3 * v * v) * n0);
  }
  EXPECT_TRUE(monge_jet_fit_point(x0, n0, spread, 6).valid);
}
