#include "bendlab/surfaces/surface_of_revolution.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include "bendlab/surfaces/taylor_jet.hpp"

namespace bendlab {

namespace {

constexpr double kPi = 3.14159265358979323846;

// Below this |sin t| the ratio H'(t) / sin t is replaced by its limit H''(t) / cos t. Both are
// even in the distance u from the pole, so they differ by O(u^2) ~ 1e-16; above it the ratio
// itself is accurate to rounding, since H' (odd about the pole) is computed without cancellation.
constexpr double kPoleSin = 1e-8;

template <int N>
Jet<N> polynomial(const std::vector<double>& coeffs, const Jet<N>& w) {
  Jet<N> p;
  for (auto it = coeffs.rbegin(); it != coeffs.rend(); ++it) p = p * w + *it;
  return p;
}

double polynomial(const std::vector<double>& coeffs, double w) {
  double p = 0.0;
  for (auto it = coeffs.rbegin(); it != coeffs.rend(); ++it) p = p * w + *it;
  return p;
}

std::vector<double> derivative_coeffs(const std::vector<double>& coeffs) {
  std::vector<double> d;
  for (std::size_t k = 1; k < coeffs.size(); ++k) d.push_back(static_cast<double>(k) * coeffs[k]);
  return d;
}

// Maximum of g on [lo, hi] by golden-section search (g unimodal there).
template <class F>
double golden_max(F&& g, double lo, double hi) {
  const double invphi = (std::sqrt(5.0) - 1.0) / 2.0;
  double a = lo, b = hi;
  double x1 = b - invphi * (b - a), x2 = a + invphi * (b - a);
  double g1 = g(x1), g2 = g(x2);
  double best = std::max({g(lo), g(hi), g1, g2});
  for (int it = 0; it < 200 && b - a > 1e-13; ++it) {
    if (g1 < g2) {
      a = x1;
      x1 = x2;
      g1 = g2;
      x2 = a + invphi * (b - a);
      g2 = g(x2);
      best = std::max(best, g2);
    } else {
      b = x2;
      x2 = x1;
      g2 = g1;
      x1 = b - invphi * (b - a);
      g1 = g(x1);
      best = std::max(best, g1);
    }
  }
  return best;
}

// Maximum of g over [0, pi]: dense samples, then the largest local maxima of the samples
// refined on their bracketing intervals.
template <class F>
double curve_max(F&& g) {
  constexpr int n = 2000;
  std::vector<double> t(n + 1), v(n + 1);
  for (int i = 0; i <= n; ++i) {
    t[i] = kPi * i / n;
    v[i] = g(t[i]);
  }
  double best = *std::max_element(v.begin(), v.end());
  std::vector<std::pair<double, int>> peaks;
  for (int i = 0; i <= n; ++i) {
    const bool up = i == 0 || v[i] > v[i - 1];
    const bool down = i == n || v[i] >= v[i + 1];
    if (up && down) peaks.emplace_back(v[i], i);
  }
  std::sort(peaks.begin(), peaks.end(), [](auto& a, auto& b) { return a.first > b.first; });
  if (peaks.size() > 8) peaks.resize(8);  // a constant (sphere) has no peaks; noise has many
  for (const auto& [val, i] : peaks) {
    if (val < 0.5 * best) break;
    best = std::max(best, golden_max(g, t[std::max(i - 1, 0)], t[std::min(i + 1, n)]));
  }
  return best;
}

}  // namespace

SurfaceOfRevolution::SurfaceOfRevolution(std::string name, double A, std::vector<double> z_coeffs,
                                         SphereMap map)
    : name_(std::move(name)), A_(A), zc_(std::move(z_coeffs)), map_(map) {
  if (!(std::isfinite(A_) && A_ > 0.0))
    throw Error("surface '" + name_ + "': the radial scale must be positive and finite");
  if (zc_.empty()) throw Error("surface '" + name_ + "': no height coefficients");
  for (double c : zc_)
    if (!std::isfinite(c)) throw Error("surface '" + name_ + "': non-finite height coefficient");
  // Z must stay positive on [0, 1] for t(x) to be defined; checked on a fine grid (the shapes
  // built here have Z constant or quadratic).
  for (int i = 0; i <= 1000; ++i)
    if (!(height_factor(i / 1000.0) > 0.0))
      throw Error("surface '" + name_ + "': the height factor must be positive");
}

double SurfaceOfRevolution::height_factor(double w) const { return polynomial(zc_, w); }

MeridianValues SurfaceOfRevolution::meridian(double t) const {
  return meridian_sc(std::sin(t), std::cos(t));
}

MeridianValues SurfaceOfRevolution::meridian_sc(double sin_t, double cos_t) const {
  const double len = std::hypot(sin_t, cos_t);
  const double s = std::abs(sin_t) / len, c = cos_t / len;

  // Taylor series in h of the curve at t + h, to 4th order (H needs 2nd derivatives of the
  // curve, lapH two more).
  Jet<4> S, C;
  Jet<4>::sin_cos(s, c, S, C);
  const Jet<4> w = S * S;
  const Jet<4> Z = polynomial(zc_, w);
  const Jet<4> Zw = polynomial(derivative_coeffs(zc_), w);
  const Jet<4> r = A_ * S;
  const Jet<4> z = C * Z;
  const Jet<3> r1 = derivative(r), z1 = derivative(z);
  const Jet<2> r2 = derivative(r1), z2 = derivative(z1);
  // z' = sin t * B exactly (chain rule on cos t Z(sin^2 t)).
  const Jet<2> B = truncate<2>(-Z + 2.0 * (C * C * Zw));

  const Jet<3> sp = sqrt(r1 * r1 + z1 * z1);  // s'(t + h)
  const Jet<2> sp2 = truncate<2>(sp);
  // Principal curvatures with the outward normal (-z', r') / s': on a sphere both are +1/R.
  const Jet<2> c1 = (truncate<2>(z1) * r2 - truncate<2>(r1) * z2) / (sp2 * sp2 * sp2);
  const Jet<2> c2 = -B / (A_ * sp2);
  const Jet<2> H = 0.5 * (c1 + c2);

  MeridianValues m;
  m.r = r.c[0];
  m.z = z.c[0];
  m.ds_dt = sp.c[0];
  m.n_r = -s * B.c[0] / sp.c[0];
  m.n_z = r1.c[0] / sp.c[0];
  m.c1 = c1.c[0];
  m.c2 = c2.c[0];
  m.H = H.c[0];
  m.K = c1.c[0] * c2.c[0];

  // Laplace-Beltrami of an axisymmetric function: lapH = 1/(r s') d/dt (r H' / s')
  //   = [ (r'/r) H' + H'' - H' s''/s' ] / s'^2,   r'/r = cos t / sin t.
  const double Hp = H.derivative(1), Hpp = H.derivative(2);
  const double s1 = sp.derivative(0), s2 = sp.derivative(1);
  const double Hp_over_sin = s > kPoleSin ? Hp / s : Hpp / c;
  m.lapH = (c * Hp_over_sin + Hpp - Hp * s2 / s1) / (s1 * s1);
  return m;
}

double SurfaceOfRevolution::parameter_of(const Vec3& x) const {
  const double rho = std::hypot(x.x(), x.y()) / A_;
  const double cos_t = x.z() / height_factor(std::min(rho * rho, 1.0));
  return std::atan2(rho, cos_t);
}

SurfaceValues SurfaceOfRevolution::from_meridian(const MeridianValues& m, double cos_phi,
                                                 double sin_phi, double kappa_b) const {
  SurfaceValues v;
  v.normal = Vec3(m.n_r * cos_phi, m.n_r * sin_phi, m.n_z);
  v.H = m.H;
  v.K = m.K;
  v.lapH = m.lapH;
  v.f_normal = kappa_b * m.f_normal_per_kb();
  v.f = v.f_normal * v.normal;
  return v;
}

SurfaceValues SurfaceOfRevolution::at(const Vec3& x, double kappa_b) const {
  // (rho, cos t) is a multiple of (sin t, cos t); no angle is formed, which keeps points next to
  // the south pole (t near pi, where t itself carries an absolute rounding of 4e-16) exact.
  const double rxy = std::hypot(x.x(), x.y());
  const double rho = rxy / A_;
  const double cos_t = x.z() / height_factor(std::min(rho * rho, 1.0));
  const MeridianValues m = meridian_sc(rho, cos_t);
  const double cphi = rxy > 0.0 ? x.x() / rxy : 1.0;
  const double sphi = rxy > 0.0 ? x.y() / rxy : 0.0;
  return from_meridian(m, cphi, sphi, kappa_b);
}

double SurfaceOfRevolution::offset(const Vec3& x) const {
  // at() identifies x with the curve point of direction (rho, cos t); measure the distance in the
  // meridian plane from (|x_xy|, z) to that point (A sin t, cos t Z(sin^2 t)).
  const double rxy = std::hypot(x.x(), x.y());
  const double rho = rxy / A_;
  const double cos_t = x.z() / height_factor(std::min(rho * rho, 1.0));
  const double norm = std::hypot(rho, cos_t);
  if (!(norm > 0)) return std::hypot(rxy, x.z()) + A_;  // the origin (or NaN): on no surface
  const double st = rho / norm, ct = cos_t / norm;
  return std::hypot(rxy - A_ * st, x.z() - ct * height_factor(st * st));
}

double SurfaceOfRevolution::size() const {
  double zmax = 0;
  for (int k = 0; k <= 100; ++k) zmax = std::max(zmax, height_factor(k / 100.0));
  return std::max(A_, zmax);
}

SurfaceValues SurfaceOfRevolution::at_angles(double t, double phi, double kappa_b) const {
  return from_meridian(meridian(t), std::cos(phi), std::sin(phi), kappa_b);
}

SurfaceOfRevolution::Integrals SurfaceOfRevolution::integrals() const {
  // Gauss-Legendre nodes on [0, pi] by Newton on P_n; the integrands 2 pi r s' and 2 pi H r s'
  // are analytic in t.
  constexpr int n = 400;
  Integrals out;
  for (int i = 0; i < n; ++i) {
    double x = std::cos(kPi * (i + 0.75) / (n + 0.5)), dp = 1;
    for (int it = 0; it < 100; ++it) {
      double p0 = 1, p1 = x;
      for (int k = 2; k <= n; ++k) {
        const double p2 = ((2 * k - 1) * x * p1 - (k - 1) * p0) / k;
        p0 = p1, p1 = p2;
      }
      dp = n * (x * p1 - p0) / (x * x - 1);
      const double dx = p1 / dp;
      x -= dx;
      if (std::abs(dx) < 1e-16) break;
    }
    const double w = kPi / ((1 - x * x) * dp * dp);
    const MeridianValues m = meridian(0.5 * kPi * (1 + x));
    const double da = 2 * kPi * m.r * m.ds_dt * w;
    out.area += da;
    out.mean_curvature += m.H * da;
  }
  return out;
}

double SurfaceOfRevolution::max_force_density(double c0, double kappa_b, double lambda) const {
  return curve_max([&](double t) {
    const MeridianValues m = meridian(t);
    // docs/conventions.md §5 (bending_parameters.hpp's membrane_normal_force; surfaces do not
    // depend on the bending module).
    return std::abs(2.0 * kappa_b * (m.lapH + 2.0 * (m.H - c0) * (m.H * m.H + c0 * m.H - m.K)) - lambda * m.K);
  });
}

SurfaceMaxima SurfaceOfRevolution::maxima(double kappa_b) const {
  std::call_once(maxima_once_, [this] {
    SurfaceMaxima& mx = maxima_unit_kb_;
    mx.H = curve_max([this](double t) { return std::abs(meridian(t).H); });
    mx.K = curve_max([this](double t) { return std::abs(meridian(t).K); });
    mx.lapH = curve_max([this](double t) { return std::abs(meridian(t).lapH); });
    mx.f = curve_max([this](double t) { return std::abs(meridian(t).f_normal_per_kb()); });
  });
  SurfaceMaxima out = maxima_unit_kb_;
  out.f *= std::abs(kappa_b);
  return out;
}

Points SurfaceOfRevolution::map_from_unit_sphere(const Points& p) const {
  Points out(p.rows(), 3);
  for (Eigen::Index i = 0; i < p.rows(); ++i) {
    const double x = p(i, 0), y = p(i, 1), z = p(i, 2);
    out(i, 0) = A_ * x;
    out(i, 1) = A_ * y;
    if (map_ == SphereMap::Scale) {
      out(i, 2) = height_factor(0.0) * z;
    } else {
      const double rho = std::min(std::hypot(x, y), 1.0);
      const double sign = z > 0.0 ? 1.0 : (z < 0.0 ? -1.0 : 0.0);
      out(i, 2) = sign * std::sqrt(1.0 - rho * rho) * height_factor(rho * rho);
    }
  }
  return out;
}

}  // namespace bendlab
