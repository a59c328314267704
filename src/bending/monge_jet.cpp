#include "bendlab/bending/monge_jet.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <mutex>

#include <omp.h>

#include "bendlab/bending/monge_jet_solve.hpp"
#include "bendlab/bending/variational_assembly.hpp"
#include "bendlab/geometry/mesh_geometry.hpp"
#include "bendlab/mesh/neighbourhood.hpp"

namespace bendlab {

namespace {

/// Smallest admissible ratio min_k L_kk^2 / max_k M_kk of the Cholesky factor L of the scaled
/// normal matrix M: below it the support is taken not to determine the jet. The scaled design
/// matrices of the paper's meshes have condition numbers 5e2-4e3 (the spec), so M's are below
/// about 2e7; 1e-12 refuses only configurations some 1e5 times worse than that.
constexpr double kMinPivotRatio = kJetMinPivotRatio;  // 1e-12, shared with the batched solve

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

/// Steps 1 and 3's chart: the frame (t1, t2, n0) of fit, the support's chart coordinates (u, v, w)
/// and the scale s = RMS |(u, v)|. false when s is 0 (every point on the normal line).
bool make_chart(const Vec3& x0, const Vec3& n0, std::span<const Vec3> support, MongeJetFit& fit,
                std::vector<Eigen::Vector3d>& uvw) {
  const int m = static_cast<int>(support.size());
  fit.points = m;
  fit.n0 = n0.normalized();
  fit.t1 = fit.n0.unitOrthogonal();
  fit.t2 = fit.n0.cross(fit.t1);
  uvw.resize(m);
  double sum_r2 = 0;
  for (int j = 0; j < m; ++j) {
    const Vec3 d = support[j] - x0;
    uvw[j] = Eigen::Vector3d(d.dot(fit.t1), d.dot(fit.t2), d.dot(fit.n0));
    sum_r2 += uvw[j][0] * uvw[j][0] + uvw[j][1] * uvw[j][1];
  }
  fit.scale = std::sqrt(sum_r2 / m);
  return fit.scale > 0;
}

/// Steps 4-5: the height derivatives at the node from the coefficients c_k = c[k * stride] of the
/// scaled jet, then n, H, K and Lap_S H of the graph; marks the fit valid.
void finish_fit(MongeJetFit& fit, int degree, const double* c, int stride) {
  const double inv_s = 1.0 / fit.scale;
  // d^a_u d^b_v h(0) = a! b! c_ab / s^(a+b), orders 1 to 4 (zero above the jet's degree).
  const std::array<double, 5> inv_s_pow{1.0, inv_s, inv_s * inv_s, inv_s * inv_s * inv_s,
                                        (inv_s * inv_s) * (inv_s * inv_s)};
  auto deriv = [&](int a_, int b_) {
    if (a_ + b_ > degree) return 0.0;
    return factorial(a_) * factorial(b_) * c[monomial_index(a_, b_) * stride] * inv_s_pow[a_ + b_];
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
  fit.degree = degree;
  fit.valid = true;
}

/// The fit of METHOD_M.md steps 3-5 for a jet of degree D, one node at a time (the reference).
template <int D>
MongeJetFit fit_jet(const Vec3& x0, const Vec3& n0_in, std::span<const Vec3> support, bool gaussian_weights,
                   Accumulation accumulation) {
  constexpr int P = unknowns_of(D);
  using Mat = Eigen::Matrix<double, P, P>;
  using Vec = Eigen::Matrix<double, P, 1>;
  const int m = static_cast<int>(support.size());
  if (m < P) return invalid_fit(m);

  MongeJetFit fit;
  thread_local std::vector<Eigen::Vector3d> uvw;
  if (!make_chart(x0, n0_in, support, fit, uvw)) return invalid_fit(m);
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
  finish_fit(fit, D, c.data(), 1);
  return fit;
}

/// Steps 3-5 at up to kJetLanes nodes side by side (monge_jet_solve.hpp): the charts and samples
/// one node at a time, the normal equations of all of them in SIMD lanes; out[l] is node l's fit.
void fit_lanes(std::span<const MongeJetNode> nodes, int degree, bool gaussian_weights, MongeJetFit* out,
               std::vector<double>* stencil_weights = nullptr) {
  thread_local JetLaneSamples samples;
  const int unknowns = unknowns_of(degree);
  int count = 0;
  for (const MongeJetNode& node : nodes) count = std::max(count, static_cast<int>(node.support.size()));
  samples.reset(count);
  std::array<bool, kJetLanes> active{};
  for (std::size_t l = 0; l < nodes.size(); ++l) {
    const MongeJetNode& node = nodes[l];
    const int m = static_cast<int>(node.support.size());
    MongeJetFit& fit = out[l];
    fit = MongeJetFit{};
    if (m < unknowns) {
      fit = invalid_fit(m);
      continue;
    }
    // make_chart's arithmetic, written straight into the lane.
    fit.points = m;
    fit.n0 = node.n0.normalized();
    fit.t1 = fit.n0.unitOrthogonal();
    fit.t2 = fit.n0.cross(fit.t1);
    double* xi = samples.xi.data() + l;
    double* eta = samples.eta.data() + l;
    double* height = samples.height.data() + l;
    double sum_r2 = 0;
    for (int j = 0; j < m; ++j) {
      const Vec3 d = node.support[j] - node.x0;
      const double u = d.dot(fit.t1), v = d.dot(fit.t2);
      xi[j * kJetLanes] = u;
      eta[j * kJetLanes] = v;
      height[j * kJetLanes] = d.dot(fit.n0);
      sum_r2 += u * u + v * v;
    }
    fit.scale = std::sqrt(sum_r2 / m);
    if (!(fit.scale > 0)) {
      fit = invalid_fit(m);
      for (int j = 0; j < m; ++j) xi[j * kJetLanes] = eta[j * kJetLanes] = height[j * kJetLanes] = 0.0;
      continue;
    }
    const double inv_s = 1.0 / fit.scale;
    for (int j = 0; j < m; ++j) xi[j * kJetLanes] *= inv_s, eta[j * kJetLanes] *= inv_s;
    double* weight = samples.weight.data() + l;
    if (gaussian_weights)
      for (int j = 0; j < m; ++j)
        weight[j * kJetLanes] = std::exp(-0.5 * (xi[j * kJetLanes] * xi[j * kJetLanes] + eta[j * kJetLanes] * eta[j * kJetLanes]));
    else
      for (int j = 0; j < m; ++j) weight[j * kJetLanes] = 1.0;
    active[l] = true;
  }
  std::array<double, unknowns_of(6) * kJetLanes> coefficients, laplacian_y;
  std::array<bool, kJetLanes> determined{};
  std::array<double, kJetLanes> inv_scale;
  for (int l = 0; l < kJetLanes; ++l)
    inv_scale[l] = l < static_cast<int>(nodes.size()) && active[l] ? 1.0 / out[l].scale : 1.0;
  solve_jet_lanes(degree, samples, coefficients.data(), determined.data(),
                  stencil_weights ? inv_scale.data() : nullptr, stencil_weights ? laplacian_y.data() : nullptr);
  for (std::size_t l = 0; l < nodes.size(); ++l) {
    if (!active[l]) continue;
    if (!determined[l]) {
      out[l] = invalid_fit(out[l].points);
      continue;
    }
    finish_fit(out[l], degree, coefficients.data() + l, kJetLanes);
    if (!stencil_weights) continue;
    // The operator's weight on support point j: w_j phi_j . y (solve_jet_lanes).
    const int m = static_cast<int>(nodes[l].support.size());
    std::vector<double>& weights = stencil_weights[l];
    weights.resize(m);
    for (int j = 0; j < m; ++j) {
      const double xi = samples.xi[j * kJetLanes + l], eta = samples.eta[j * kJetLanes + l];
      std::array<double, 7> pu, pv;
      pu[0] = pv[0] = 1;
      for (int k = 1; k <= degree; ++k) pu[k] = pu[k - 1] * xi, pv[k] = pv[k - 1] * eta;
      double sum = 0;
      for (int k = 1; k <= degree; ++k)
        for (int b = 0; b <= k; ++b) sum += pu[k - b] * pv[b] * laplacian_y[monomial_index(k - b, b) * kJetLanes + l];
      weights[j] = samples.weight[j * kJetLanes + l] * sum;
    }
  }
}

/// Positions of a VertexRings list, in a buffer reused from node to node.
std::span<const Vec3> gather(const Points& x, const std::vector<int>& v, std::vector<Vec3>& buffer) {
  buffer.resize(v.size());
  for (std::size_t k = 0; k < v.size(); ++k) buffer[k] = x.row(v[k]).transpose();
  return buffer;
}

/// Step 2's trim of `items` (support points, or their vertex indices), `d2` an item's squared
/// distance from the node: the `count` nearest and every item as near as the last of them (to
/// 1e-9 relative); count 0 or a smaller support: unchanged.
template <class Item, class SquaredDistance>
void trim_nearest(int count, std::vector<Item>& items, SquaredDistance d2) {
  if (count <= 0 || static_cast<int>(items.size()) <= count) return;
  std::nth_element(items.begin(), items.begin() + (count - 1), items.end(),
                   [&](const Item& p, const Item& q) { return d2(p) < d2(q); });
  const double cut = d2(items[count - 1]) * (1 + 1e-9);
  items.erase(std::partition(items.begin(), items.end(), [&](const Item& p) { return d2(p) <= cut; }), items.end());
}

void check_settings(const MongeJetSettings& s) {
  if (s.degree < 4 || s.degree > 6)
    throw Error(fmt::format("method M: degree must be 4, 5 or 6, got {}", s.degree));
  if (s.rings < 2 || s.rings > 3) throw Error(fmt::format("method M: support_rings must be 2 or 3, got {}", s.rings));
  if (s.support_points != 0 && s.support_points < monge_jet_min_points(s.degree))
    throw Error(fmt::format("method M: support_points must be 0 (keep the rings whole) or at least {} (the {} "
                            "unknowns of a degree-{} jet + 4), got {}",
                            monge_jet_min_points(s.degree), monge_jet_unknowns(s.degree), s.degree,
                            s.support_points));
}

/// The weights l_j of Lap_S w at the node of `fit` (monge_jet_laplacian) for a jet of degree D on the
/// support `support` (positions), into `weights` (one per support point).
template <int D>
void laplacian_weights(const MongeJetFit& fit, const Vec3& x0, std::span<const Vec3> support, bool gaussian_weights,
                       std::vector<double>& weights) {
  constexpr int P = unknowns_of(D);
  using Mat = Eigen::Matrix<double, P, P>;
  using Vec = Eigen::Matrix<double, P, 1>;
  const int m = static_cast<int>(support.size());
  thread_local std::vector<Vec> phi;
  thread_local std::vector<double> w;
  phi.resize(m);
  w.resize(m);
  const double inv_s = 1.0 / fit.scale;
  Mat a = Mat::Zero();
  for (int j = 0; j < m; ++j) {
    const Vec3 d = support[j] - x0;
    const double xi = d.dot(fit.t1) * inv_s, eta = d.dot(fit.t2) * inv_s;
    std::array<double, D + 1> pu, pv;
    pu[0] = pv[0] = 1;
    for (int k = 1; k <= D; ++k) pu[k] = pu[k - 1] * xi, pv[k] = pv[k - 1] * eta;
    for (int k = 1; k <= D; ++k)
      for (int b = 0; b <= k; ++b) phi[j][monomial_index(k - b, b)] = pu[k - b] * pv[b];
    w[j] = gaussian_weights ? std::exp(-0.5 * (xi * xi + eta * eta)) : 1.0;
    a.noalias() += (w[j] * phi[j]) * phi[j].transpose();
  }
  // Lap_S w = g^ab w_ab - T (grad h . grad w) / W^2 (farutin.cpp's derivation), T = g^ab h_ab,
  // g^-1 = I - grad h grad h^T / W^2, W^2 = 1 + |grad h|^2, with w_u = c_10 / s, w_v = c_01 / s,
  // w_uu = 2 c_20 / s^2, w_uv = c_11 / s^2, w_vv = 2 c_02 / s^2: l . c for the coefficients c.
  const HeightDerivatives& h = fit.derivatives;
  const double w2 = 1 + h.u * h.u + h.v * h.v;
  const double g11 = 1 - h.u * h.u / w2, g12 = -h.u * h.v / w2, g22 = 1 - h.v * h.v / w2;
  const double tr = g11 * h.uu + 2 * g12 * h.uv + g22 * h.vv;
  Vec l = Vec::Zero();
  l[monomial_index(1, 0)] = -tr * h.u / w2 * inv_s;
  l[monomial_index(0, 1)] = -tr * h.v / w2 * inv_s;
  l[monomial_index(2, 0)] = 2 * g11 * inv_s * inv_s;
  l[monomial_index(1, 1)] = 2 * g12 * inv_s * inv_s;
  l[monomial_index(0, 2)] = 2 * g22 * inv_s * inv_s;
  // c = M^-1 sum_j w_j phi_j (w_j - w_i): l . c = sum_j [w_j phi_j . (M^-1 l)] (w_j - w_i).
  const Vec y = Eigen::LLT<Mat>(a).solve(l);
  weights.resize(m);
  for (int j = 0; j < m; ++j) weights[j] = w[j] * phi[j].dot(y);
}

void laplacian_weights(const MongeJetFit& fit, const Vec3& x0, std::span<const Vec3> support, int degree,
                       bool gaussian_weights, std::vector<double>& weights) {
  switch (degree) {
    case 2: return laplacian_weights<2>(fit, x0, support, gaussian_weights, weights);
    case 3: return laplacian_weights<3>(fit, x0, support, gaussian_weights, weights);
    case 4: return laplacian_weights<4>(fit, x0, support, gaussian_weights, weights);
    case 5: return laplacian_weights<5>(fit, x0, support, gaussian_weights, weights);
    default: return laplacian_weights<6>(fit, x0, support, gaussian_weights, weights);
  }
}

}  // namespace

void monge_jet_laplacian(const Topology& t, const Points& x, const MongeJetSettings& settings,
                         const MongeJetSupports& lists, const std::vector<MongeJetFit>& fits, const Scalars& field,
                         Scalars& out) {
  const int n = t.num_vertices();
  if (static_cast<int>(fits.size()) != n || field.size() != n)
    throw Error("monge_jet_laplacian: the fits and the field must have one entry per vertex");
  out.resize(n);
#pragma omp parallel
  {
    std::vector<int> ids;
    std::vector<Vec3> support;
    std::vector<double> weights;
#pragma omp for schedule(static)
    for (int i = 0; i < n; ++i) {
      const MongeJetFit& fit = fits[i];
      const Vec3 x0 = x.row(i).transpose();
      // The support of the fit: the rings' list trimmed as in monge_jet_fit.
      ids.assign(lists.vertices.begin() + lists.offsets[i], lists.vertices.begin() + lists.offsets[i + 1]);
      trim_nearest(settings.support_points, ids, [&](int v) { return (Vec3(x.row(v).transpose()) - x0).squaredNorm(); });
      support.resize(ids.size());
      for (std::size_t k = 0; k < ids.size(); ++k) support[k] = x.row(ids[k]).transpose();
      laplacian_weights(fit, x0, support, fit.degree, settings.gaussian_weights, weights);
      double sum = 0;
      for (std::size_t k = 0; k < ids.size(); ++k) sum += weights[k] * (field[ids[k]] - field[i]);
      out[i] = sum;
    }
  }
}

int monge_jet_unknowns(int degree) { return unknowns_of(degree); }

int monge_jet_min_points(int degree) { return unknowns_of(degree) + 4; }

Vec3 covariance_normal(const Vec3& x0, std::span<const Vec3> points, const Vec3& orientation) {
  Mat3 c = Mat3::Zero();
  for (const Vec3& p : points) {
    const Vec3 d = p - x0;
    c.noalias() += d * d.transpose();
  }
  // Eigenvalues in increasing order: column 0 belongs to the smallest. The closed-form 3x3 solver
  // (a fifth of the iterative one's time) computes the most distinct eigenvalue's vector first,
  // which here is the normal's: the two tangential eigenvalues are close, the normal's far below.
  Eigen::SelfAdjointEigenSolver<Mat3> eig;
  eig.computeDirect(c);
  Vec3 n = eig.eigenvectors().col(0);
  if (n.dot(orientation) < 0) n = -n;
  return n;
}

MongeJetFit monge_jet_fit_point(const Vec3& x0, const Vec3& n0, std::span<const Vec3> support, int degree,
                                bool gaussian_weights, Accumulation accumulation) {
  switch (degree) {
    case 2: return fit_jet<2>(x0, n0, support, gaussian_weights, accumulation);
    case 3: return fit_jet<3>(x0, n0, support, gaussian_weights, accumulation);
    case 4: return fit_jet<4>(x0, n0, support, gaussian_weights, accumulation);
    case 5: return fit_jet<5>(x0, n0, support, gaussian_weights, accumulation);
    case 6: return fit_jet<6>(x0, n0, support, gaussian_weights, accumulation);
    default: throw Error(fmt::format("method M: a jet's degree must be 2 to 6, got {}", degree));
  }
}

MongeJetFit monge_jet_fallback_fit(const Vec3& x0, const Vec3& n0, std::span<const Vec3> support,
                                   const MongeJetSettings& settings) {
  MongeJetFit fit;
  for (int degree : {4, 2}) {
    if (degree >= settings.degree) continue;
    fit = monge_jet_fit_point(x0, n0, support, degree, settings.gaussian_weights);
    if (fit.valid) break;
  }
  return fit;
}

std::vector<MongeJetFit> monge_jet_fit_nodes(std::span<const MongeJetNode> nodes, int degree,
                                             bool gaussian_weights) {
  if (degree < 4 || degree > 6) throw Error(fmt::format("method M: degree must be 4, 5 or 6, got {}", degree));
  std::vector<MongeJetFit> fits(nodes.size());
  for (std::size_t first = 0; first < nodes.size(); first += kJetLanes)
    fit_lanes(nodes.subspan(first, std::min<std::size_t>(kJetLanes, nodes.size() - first)), degree,
              gaussian_weights, fits.data() + first);
  return fits;
}

MongeJetSupports MongeJetSupports::build(const Topology& t, const MongeJetSettings& settings) {
  check_settings(settings);
  const int n = t.num_vertices();
  const int min_points = monge_jet_min_points(settings.degree);
  MongeJetSupports s;
  s.faces = t.faces();
  s.rings = settings.rings;
  s.min_points = min_points;
  s.two_ring.resize(n);
  s.rings_used.resize(n);
  std::vector<std::vector<int>> lists(n);
#pragma omp parallel
  {
    VertexRings nb(t);
#pragma omp for schedule(static)
    for (int i = 0; i < n; ++i) {
      nb.start(i);
      nb.grow_to(2);
      s.two_ring[i] = static_cast<int>(nb.vertices().size());
      nb.grow_to(settings.rings);
      bool more = true;
      while (more && static_cast<int>(nb.vertices().size()) < min_points) more = nb.add_ring();
      lists[i] = nb.vertices();
      s.rings_used[i] = nb.rings();
    }
  }
  s.offsets.assign(n + 1, 0);
  for (int i = 0; i < n; ++i) s.offsets[i + 1] = s.offsets[i] + static_cast<int>(lists[i].size());
  s.vertices.reserve(s.offsets[n]);
  for (const auto& list : lists) s.vertices.insert(s.vertices.end(), list.begin(), list.end());
  return s;
}

bool MongeJetSupports::matches(const Topology& t, const MongeJetSettings& settings) const {
  return t.num_vertices() + 1 == static_cast<int>(offsets.size()) && rings == settings.rings &&
         min_points == monge_jet_min_points(settings.degree) && t.faces() == faces;
}

std::vector<MongeJetFit> monge_jet_fit(const Topology& t, const Points& x, const Points& mwa_normal,
                                       const MongeJetSettings& settings) {
  return monge_jet_fit(t, x, mwa_normal, settings, MongeJetSupports::build(t, settings));
}

std::vector<MongeJetFit> monge_jet_fit(const Topology& t, const Points& x, const Points& mwa_normal,
                                       const MongeJetSettings& settings, const MongeJetSupports& lists) {
  MongeJetWorkspace ws;
  std::vector<MongeJetFit> fits;
  monge_jet_fit(t, x, mwa_normal, settings, lists, ws, fits);
  return fits;
}

// One thread's buffers: its neighbourhood (for one topology), the supports of a batch of nodes.
struct MongeJetWorkspace::Thread {
  explicit Thread(const Topology& t) : topology_id(t.id()), nb(t) {}
  std::uint64_t topology_id;  // Topology::id(): the address may be a later topology's
  VertexRings nb;
  std::vector<Vec3> buffer;
  std::array<std::vector<Vec3>, kJetLanes> supports;
  std::array<std::vector<int>, kJetLanes> ids;  // the supports' vertices
  std::array<MongeJetNode, kJetLanes> nodes;
};

MongeJetWorkspace::MongeJetWorkspace() = default;
MongeJetWorkspace::~MongeJetWorkspace() = default;

void MongeJetWorkspace::prepare() {
  const auto n = static_cast<std::size_t>(omp_get_max_threads());
  if (threads_.size() < n) threads_.resize(n);
}

MongeJetWorkspace::Thread& MongeJetWorkspace::thread(int k, const Topology& topology) {
  std::unique_ptr<Thread>& slot = threads_[k];
  if (!slot || slot->topology_id != topology.id()) slot = std::make_unique<Thread>(topology);
  return *slot;
}

void MongeJetLaplacianStencil::apply(const Scalars& w, Scalars& out) const {
  const auto n = static_cast<Eigen::Index>(ids.size());
  if (w.size() != n || static_cast<Eigen::Index>(weights.size()) != n)
    throw Error("Method M's Laplacian stencil: the field must have one entry per vertex of the stencil");
  out.resize(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const std::vector<int>& id = ids[i];
    const std::vector<double>& c = weights[i];
    double sum = 0;
    for (std::size_t k = 0; k < id.size(); ++k) sum += c[k] * (w[id[k]] - w[i]);
    out[i] = sum;
  }
}

void monge_jet_fit(const Topology& t, const Points& x, const Points& mwa_normal, const MongeJetSettings& settings,
                   const MongeJetSupports& lists, MongeJetWorkspace& ws, std::vector<MongeJetFit>& fits,
                   MongeJetLaplacianStencil* stencil) {
  check_settings(settings);
  if (!lists.matches(t, settings))
    throw Error("method M: the support lists were built for another mesh connectivity or other options");
  const int n = t.num_vertices();
  fits.resize(n);
  if (stencil) {
    stencil->ids.resize(n);
    stencil->weights.resize(n);
  }
  // kJetLanes nodes at a time: their supports one by one, their fits side by side (fit_lanes).
  const int batches = (n + kJetLanes - 1) / kJetLanes;
  ws.prepare();
#pragma omp parallel
  {
    MongeJetWorkspace::Thread& scratch = ws.thread(omp_get_thread_num(), t);
    VertexRings& nb = scratch.nb;
    std::vector<Vec3>& buffer = scratch.buffer;
    std::array<std::vector<Vec3>, kJetLanes>& supports = scratch.supports;
    std::array<std::vector<int>, kJetLanes>& ids = scratch.ids;
    std::array<MongeJetNode, kJetLanes>& nodes = scratch.nodes;
#pragma omp for schedule(static)
    for (int b = 0; b < batches; ++b) {
      const int first = b * kJetLanes, count = std::min(kJetLanes, n - first);
      for (int l = 0; l < count; ++l) {
        // The support of step 2 (rings listed ring after ring, so the frame's 2-ring is a prefix).
        const int i = first + l;
        std::vector<int>& id = ids[l];
        id.assign(lists.vertices.begin() + lists.offsets[i], lists.vertices.begin() + lists.offsets[i + 1]);
        std::vector<Vec3>& support = supports[l];
        gather(x, id, support);
        const Vec3 x0 = x.row(i).transpose(), mwa = mwa_normal.row(i).transpose();
        const Vec3 n0 = settings.frame == MongeFrame::AngleWeighted
                            ? mwa
                            : covariance_normal(x0, std::span<const Vec3>(support).first(lists.two_ring[i]), mwa);
        if (settings.support_points > 0 && static_cast<int>(id.size()) > settings.support_points) {
          trim_nearest(settings.support_points, id,
                       [&](int v) { return (Vec3(x.row(v).transpose()) - x0).squaredNorm(); });
          gather(x, id, support);
        }
        nodes[l] = MongeJetNode{x0, n0, support};
      }
      fit_lanes(std::span<const MongeJetNode>(nodes.data(), count), settings.degree, settings.gaussian_weights,
                fits.data() + first, stencil ? stencil->weights.data() + first : nullptr);
      for (int l = 0; l < count; ++l) {
        const int i = first + l;
        MongeJetFit& fit = fits[i];
        // (A mesh too small for the jet's unknowns is refused below instead.)
        if (!fit.valid && static_cast<int>(nodes[l].support.size()) >= monge_jet_unknowns(settings.degree)) {
          fit = monge_jet_fallback_fit(nodes[l].x0, nodes[l].n0, nodes[l].support, settings);
          if (fit.valid && stencil)
            laplacian_weights(fit, nodes[l].x0, nodes[l].support, fit.degree, settings.gaussian_weights,
                              stencil->weights[i]);
        }
        fit.rings = lists.rings_used[i];
        if (stencil) stencil->ids[i] = ids[l];
      }
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
    throw Error(fmt::format("method M: the jet at vertex {} is not determined by its {} support points, neither of "
                            "degree {} nor of a lower degree down to 2 (singular least-squares system: the "
                            "neighbourhood folds over in the tangent plane)",
                            i, f.points, settings.degree));
  }
}

// Kept by the method instance and reused from call to call (method_workspace.hpp).
struct MongeJetMethod::Workspace {
  MeshGeometry geometry;
  std::vector<MongeJetFit> fits;
  MongeJetWorkspace buffers;
  MongeJetLaplacianStencil stencil;  // laplacian = field
};

MongeJetMethod::MongeJetMethod(MongeJetSettings settings) : settings_(settings) { check_settings(settings_); }
MongeJetMethod::~MongeJetMethod() = default;

std::shared_ptr<const MongeJetSupports> MongeJetMethod::supports_for(const Topology& topology) const {
  {
    std::lock_guard<std::mutex> lock(cache_mutex_);
    auto it = cache_.find(&topology);
    if (it != cache_.end() && it->second->matches(topology, settings_)) return it->second;
  }
  // Built outside the lock; a concurrent builder for the same topology does the same work once more.
  auto entry = std::make_shared<const MongeJetSupports>(MongeJetSupports::build(topology, settings_));
  std::lock_guard<std::mutex> lock(cache_mutex_);
  if (cache_.size() >= kMaxCachedTopologies && !cache_.count(&topology)) cache_.erase(cache_.begin());
  cache_[&topology] = entry;
  return entry;
}

std::unique_ptr<BendingMethod> MongeJetMethod::create(const MethodOptions& options) {
  MongeJetSettings s;
  s.degree = static_cast<int>(option_int(options, "degree"));
  s.rings = static_cast<int>(option_int(options, "support_rings"));
  s.frame = options.at("frame") == "angle-weighted" ? MongeFrame::AngleWeighted : MongeFrame::Covariance;
  s.gaussian_weights = option_bool(options, "gaussian_weights");
  s.support_points = static_cast<int>(option_int(options, "support_points"));
  s.laplacian = options.at("laplacian") == "field" ? MongeLaplacian::Field : MongeLaplacian::Jet;
  return std::make_unique<MongeJetMethod>(s);
}

MethodInfo MongeJetMethod::info() {
  MethodInfo m{"M",
               "Monge jet: degree-6 height fits on the 3-ring give n, H and K, and their Laplace-Beltrami operator applied to H "
               "gives Lap H, in eq. (10) (beyond the paper)",
               {int_option("degree", 4, 6, 6, "degree of the fitted height polynomial (4, 5 or 6)"),
                int_option("support_rings", 2, 3, 3,
                           "fitting support in rings of neighbours (widened while it has fewer than "
                           "unknowns + 4 points; where it does not determine the jet, the degree is lowered to 4, "
                           "then 2)"),
                int_option("support_points", 0, 1000, 0,
                           "keep the nearest this many points of the rings, and any as near as the last "
                           "(0: all; else at least unknowns + 4)"),
                choice_option("frame", {"covariance", "angle-weighted"}, "covariance",
                              "chart normal: smallest principal axis of the 2-ring, or the angle-weighted normal"),
                bool_option("gaussian_weights", false,
                            "weight the fit by exp(-r^2 / (2 s^2)), s the RMS distance of the support"),
                choice_option("laplacian", {"jet", "field"}, "field",
                              "Lap H from the jet's 3rd and 4th derivatives, or the jet's Laplace-Beltrami "
                              "operator applied to the field H")},
               {},
               &MongeJetMethod::create};
  m.capabilities.cost = "O(N)";
  return m;
}

void MongeJetMethod::fields(const Topology& topology, const Points& x, BendingResult& out) const {
  const std::shared_ptr<const MongeJetSupports> supports = supports_for(topology);
  const auto ws = workspace_.acquire();
  MeshGeometry& geometry = ws->geometry;
  MeshGeometry::compute(topology, x, geometry);
  const bool field = settings_.laplacian == MongeLaplacian::Field;
  monge_jet_fit(topology, x, geometry.normal_mwa, settings_, *supports, ws->buffers, ws->fits,
                field ? &ws->stencil : nullptr);
  const std::vector<MongeJetFit>& fits = ws->fits;
  const auto n = static_cast<Eigen::Index>(fits.size());
  out.normal.resize(n, 3);
  out.H.resize(n);
  out.K.resize(n);
  out.lapH.resize(n);
  long fallbacks = 0;
  for (Eigen::Index i = 0; i < n; ++i) {
    fallbacks += fits[i].degree != settings_.degree;
    out.normal.row(i) = fits[i].normal.transpose();
    out.H[i] = fits[i].H;
    out.K[i] = fits[i].K;
    out.lapH[i] = fits[i].lapH;
  }
  if (fallbacks > 0) fallbacks_.fetch_add(fallbacks, std::memory_order_relaxed);
  if (field) ws->stencil.apply(out.H, out.lapH);
  out.area.swap(geometry.mixed_area);  // no copy; next call the arrays are reused
}

}  // namespace bendlab
