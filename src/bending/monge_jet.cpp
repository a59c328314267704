#include "bendlab/bending/monge_jet.hpp"

#include <fmt/format.h>

#include <array>
#include <cmath>
#include <limits>

#include "bendlab/bending/variational_assembly.hpp"
#include "bendlab/geometry/mesh_geometry.hpp"
#include "bendlab/mesh/neighbourhood.hpp"

namespace bendlab {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
/// Smallest admissible ratio min_k L_kk^2 / max_k M_kk of the Cholesky factor L of the scaled
/// normal matrix M: below it the support is taken not to determine the jet. The scaled design
/// matrices of the paper's meshes have condition numbers 5e2-4e3 (the spec), so M's are below
/// about 2e7; 1e-12 refuses only configurations some 1e5 times worse than that.
constexpr double kMinPivotRatio = 1e-12;

constexpr int unknowns_of(int degree) { return (degree + 1) * (degree + 2) / 2 - 1; }

/// Position of the monomial u^a v^b (1 <= a + b) in the basis: by total degree k = a + b, then by b.
constexpr int monomial_index(int a, int b) { return (a + b - 1) * (a + b + 2) / 2 + b; }

constexpr double factorial(int n) { return n <= 1 ? 1.0 : n * factorial(n - 1); }

MongeJetFit invalid_fit(int points) {
  MongeJetFit f;
  f.normal = Vec3::Constant(kNaN);
  f.H = f.K = f.lapH = kNaN;
  f.points = points;
  return f;
}

/// The fit of METHOD_M.md steps 3-5 for a jet of degree D.
template <int D>
MongeJetFit fit_jet(const Vec3& x0, const Vec3& n0_in, std::span<const Vec3> support, bool gaussian_weights,
                   Accumulation accumulation) {
  constexpr int P = unknowns_of(D);
  using Mat = Eigen::Matrix<double, P, P>;
  using Vec = Eigen::Matrix<double, P, 1>;
  const int m = static_cast<int>(support.size());
  if (m < P) return invalid_fit(m);

  MongeJetFit fit;
  fit.points = m;
  fit.n0 = n0_in.normalized();
  fit.t1 = fit.n0.unitOrthogonal();
  fit.t2 = fit.n0.cross(fit.t1);

  // Chart coordinates and the length scale s = RMS |(u, v)|.
  thread_local std::vector<Eigen::Vector3d> uvw;
  uvw.resize(m);
  double sum_r2 = 0;
  for (int j = 0; j < m; ++j) {
    const Vec3 d = support[j] - x0;
    uvw[j] = Eigen::Vector3d(d.dot(fit.t1), d.dot(fit.t2), d.dot(fit.n0));
    sum_r2 += uvw[j][0] * uvw[j][0] + uvw[j][1] * uvw[j][1];
  }
  fit.scale = std::sqrt(sum_r2 / m);
  if (!(fit.scale > 0)) return invalid_fit(m);
  const double inv_s = 1.0 / fit.scale;

  // Normal equations of the scaled least-squares problem. Entry ((a,b), (c,d)) of Phi^T W Phi is the
  // moment mu_{a+c, b+d} = sum_j w_j xi_j^(a+c) eta_j^(b+d), so the fast path sums the
  // (2D+1)(2D+2)/2 moments per point (91 for degree 6) instead of the P^2 products of an outer
  // product (729), and fills the matrix from them; the reference path sums the outer products.
  Mat a;
  Vec rhs = Vec::Zero();
  if (accumulation == Accumulation::Moments) {
    std::array<double, (2 * D + 1) * (2 * D + 1)> mu{};  // mu[p * (2D+1) + q], p + q <= 2D used
    for (int j = 0; j < m; ++j) {
      const double xi = uvw[j][0] * inv_s, eta = uvw[j][1] * inv_s;
      const double w = gaussian_weights ? std::exp(-0.5 * (xi * xi + eta * eta)) : 1.0;
      std::array<double, 2 * D + 1> pu, pv;
      pu[0] = w, pv[0] = 1;
      for (int k = 1; k <= 2 * D; ++k) pu[k] = pu[k - 1] * xi, pv[k] = pv[k - 1] * eta;
      for (int p = 0; p <= 2 * D; ++p)
        for (int q = 0; p + q <= 2 * D; ++q) mu[p * (2 * D + 1) + q] += pu[p] * pv[q];
      const double hw = uvw[j][2];
      for (int k = 1; k <= D; ++k)
        for (int b = 0; b <= k; ++b) rhs[monomial_index(k - b, b)] += hw * pu[k - b] * pv[b];
    }
    for (int k1 = 1; k1 <= D; ++k1)
      for (int b1 = 0; b1 <= k1; ++b1)
        for (int k2 = 1; k2 <= D; ++k2)
          for (int b2 = 0; b2 <= k2; ++b2)
            a(monomial_index(k1 - b1, b1), monomial_index(k2 - b2, b2)) =
                mu[(k1 - b1 + k2 - b2) * (2 * D + 1) + b1 + b2];
  } else {
    a.setZero();
    for (int j = 0; j < m; ++j) {
      const double xi = uvw[j][0] * inv_s, eta = uvw[j][1] * inv_s;
      std::array<double, D + 1> pu, pv;
      pu[0] = pv[0] = 1;
      for (int k = 1; k <= D; ++k) pu[k] = pu[k - 1] * xi, pv[k] = pv[k - 1] * eta;
      Vec phi;
      for (int k = 1; k <= D; ++k)
        for (int b = 0; b <= k; ++b) phi[monomial_index(k - b, b)] = pu[k - b] * pv[b];
      const double w = gaussian_weights ? std::exp(-0.5 * (xi * xi + eta * eta)) : 1.0;
      a.noalias() += (w * phi) * phi.transpose();
      rhs += (w * uvw[j][2]) * phi;
    }
  }
  // Eigen's blocked Cholesky (vectorised), then the pivot test on the factor's diagonal.
  const Eigen::LLT<Mat> llt(a);
  if (llt.info() != Eigen::Success) return invalid_fit(m);
  const double max_diag = a.diagonal().maxCoeff();
  if (!(llt.matrixLLT().diagonal().cwiseAbs2().minCoeff() > kMinPivotRatio * max_diag)) return invalid_fit(m);
  const Vec c = llt.solve(rhs);

  // d^a_u d^b_v h(0) = a! b! c_ab / s^(a+b), orders 1 to 4 (zero above the jet's degree).
  auto deriv = [&](int a_, int b_) {
    if (a_ + b_ > D) return 0.0;
    return factorial(a_) * factorial(b_) * c[monomial_index(a_, b_)] * std::pow(inv_s, a_ + b_);
  };
  HeightDerivatives& h = fit.derivatives;
  h.u = deriv(1, 0), h.v = deriv(0, 1);
  h.uu = deriv(2, 0), h.uv = deriv(1, 1), h.vv = deriv(0, 2);
  h.uuu = deriv(3, 0), h.uuv = deriv(2, 1), h.uvv = deriv(1, 2), h.vvv = deriv(0, 3);
  h.uuuu = deriv(4, 0), h.uuuv = deriv(3, 1), h.uuvv = deriv(2, 2), h.uvvv = deriv(1, 3), h.vvvv = deriv(0, 4);

  const GraphCurvatures g = graph_curvatures(h);
  fit.normal = g.normal_local[0] * fit.t1 + g.normal_local[1] * fit.t2 + g.normal_local[2] * fit.n0;
  fit.H = g.H;
  fit.K = g.K;
  fit.lapH = g.lapH;
  fit.valid = true;
  return fit;
}

/// Positions of a VertexRings list, in a buffer reused from node to node.
std::span<const Vec3> gather(const Points& x, const std::vector<int>& v, std::vector<Vec3>& buffer) {
  buffer.resize(v.size());
  for (std::size_t k = 0; k < v.size(); ++k) buffer[k] = x.row(v[k]).transpose();
  return buffer;
}

void check_settings(const MongeJetSettings& s) {
  if (s.degree < 4 || s.degree > 6)
    throw Error(fmt::format("method M: degree must be 4, 5 or 6, got {}", s.degree));
  if (s.rings < 2 || s.rings > 3) throw Error(fmt::format("method M: support_rings must be 2 or 3, got {}", s.rings));
}

}  // namespace

int monge_jet_unknowns(int degree) { return unknowns_of(degree); }

int monge_jet_min_points(int degree) { return unknowns_of(degree) + 4; }

Vec3 covariance_normal(const Vec3& x0, std::span<const Vec3> points, const Vec3& orientation) {
  Mat3 c = Mat3::Zero();
  for (const Vec3& p : points) {
    const Vec3 d = p - x0;
    c.noalias() += d * d.transpose();
  }
  // Eigenvalues in increasing order: column 0 belongs to the smallest.
  const Eigen::SelfAdjointEigenSolver<Mat3> eig(c);
  Vec3 n = eig.eigenvectors().col(0);
  if (n.dot(orientation) < 0) n = -n;
  return n;
}

MongeJetFit monge_jet_fit_point(const Vec3& x0, const Vec3& n0, std::span<const Vec3> support, int degree,
                                bool gaussian_weights, Accumulation accumulation) {
  switch (degree) {
    case 4: return fit_jet<4>(x0, n0, support, gaussian_weights, accumulation);
    case 5: return fit_jet<5>(x0, n0, support, gaussian_weights, accumulation);
    case 6: return fit_jet<6>(x0, n0, support, gaussian_weights, accumulation);
    default: throw Error(fmt::format("method M: degree must be 4, 5 or 6, got {}", degree));
  }
}

std::vector<MongeJetFit> monge_jet_fit(const Topology& t, const Points& x, const Points& mwa_normal,
                                       const MongeJetSettings& settings) {
  check_settings(settings);
  const int n = t.num_vertices();
  const int min_points = monge_jet_min_points(settings.degree);
  std::vector<MongeJetFit> fits(n);
#pragma omp parallel
  {
    VertexRings nb(t);
    std::vector<Vec3> buffer;
#pragma omp for schedule(static)
    for (int i = 0; i < n; ++i) {
      const Vec3 x0 = x.row(i).transpose(), mwa = mwa_normal.row(i).transpose();
      nb.start(i);
      Vec3 n0 = mwa;
      if (settings.frame == MongeFrame::Covariance) {
        nb.grow_to(2);
        n0 = covariance_normal(x0, gather(x, nb.vertices(), buffer), mwa);
      }
      nb.grow_to(settings.rings);
      bool more = true;
      while (more && static_cast<int>(nb.vertices().size()) < min_points) more = nb.add_ring();
      MongeJetFit fit =
          monge_jet_fit_point(x0, n0, gather(x, nb.vertices(), buffer), settings.degree, settings.gaussian_weights);
      // A singular configuration: widen the support.
      while (!fit.valid && nb.add_ring())
        fit = monge_jet_fit_point(x0, n0, gather(x, nb.vertices(), buffer), settings.degree,
                                  settings.gaussian_weights);
      fit.rings = nb.rings();
      fits[i] = fit;
    }
  }
  const int unknowns = monge_jet_unknowns(settings.degree);
  for (int i = 0; i < n; ++i) {
    const MongeJetFit& f = fits[i];
    if (f.valid) continue;
    if (f.points < unknowns)
      throw Error(fmt::format("method M: vertex {} reaches only {} other vertices, fewer than the {} unknowns of a "
                              "degree-{} jet: the mesh is too coarse (refine it or lower the option degree)",
                              i, f.points, unknowns, settings.degree));
    throw Error(fmt::format("method M: the degree-{} jet at vertex {} is not determined by its {} support points "
                            "(singular least-squares system, even with every vertex the mesh connects to it)",
                            settings.degree, i, f.points));
  }
  return fits;
}

MongeJetMethod::MongeJetMethod(MongeJetSettings settings) : settings_(settings) { check_settings(settings_); }

std::unique_ptr<BendingMethod> MongeJetMethod::create(const MethodOptions& options) {
  MongeJetSettings s;
  s.degree = static_cast<int>(option_int(options, "degree"));
  s.rings = static_cast<int>(option_int(options, "support_rings"));
  s.frame = options.at("frame") == "angle-weighted" ? MongeFrame::AngleWeighted : MongeFrame::Covariance;
  s.gaussian_weights = option_bool(options, "gaussian_weights");
  return std::make_unique<MongeJetMethod>(s);
}

MethodInfo MongeJetMethod::info() {
  MethodInfo m{"M",
               "Monge jet: degree-6 height fit on the 3-ring gives n, H, K and Lap H in eq. (10) (beyond the paper)",
               {int_option("degree", 4, 6, 6, "degree of the fitted height polynomial (4, 5 or 6)"),
                int_option("support_rings", 2, 3, 3,
                           "fitting support in rings of neighbours (widened while it has fewer than "
                           "unknowns + 4 points or the fit is singular)"),
                choice_option("frame", {"covariance", "angle-weighted"}, "covariance",
                              "chart normal: smallest principal axis of the 2-ring, or the angle-weighted normal"),
                bool_option("gaussian_weights", false,
                            "weight the fit by exp(-r^2 / (2 s^2)), s the RMS distance of the support")},
               {},
               &MongeJetMethod::create};
  m.capabilities.cost = "O(N)";
  return m;
}

BendingResult MongeJetMethod::compute(const Topology& topology, const Points& x, double kappa_b) const {
  return compute_terms(topology, x, BendingParameters(kappa_b));  // plain: eq. (10) unchanged
}

// With c0 and ADE the force law of docs/conventions.md §5 from the same H, K, Lap H and n.
BendingResult MongeJetMethod::compute_terms(const Topology& topology, const Points& x,
                                            const BendingParameters& params) const {
  const MeshGeometry geometry = MeshGeometry::compute(topology, x);
  const std::vector<MongeJetFit> fits = monge_jet_fit(topology, x, geometry.normal_mwa, settings_);
  const auto n = static_cast<Eigen::Index>(fits.size());
  Points normal(n, 3);
  Scalars H(n), K(n), lapH(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    normal.row(i) = fits[i].normal.transpose();
    H[i] = fits[i].H;
    K[i] = fits[i].K;
    lapH[i] = fits[i].lapH;
  }
  return assemble_variational_result(std::move(normal), std::move(H), std::move(K), std::move(lapH),
                                     geometry.mixed_area, params);
}

}  // namespace bendlab
