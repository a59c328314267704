#include "bendlab/flow/bim/stokes_single_layer.hpp"

#include <fmt/format.h>

#include <Eigen/QR>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numeric>

namespace bendlab {

const TriangleRule7& triangle_rule7() {
  static const TriangleRule7 rule = [] {
    // Strang & Fix / Dunavant degree 5: centroid plus two orbits of three points.
    const double s15 = std::sqrt(15.0);
    const double a1 = (9.0 - 2.0 * s15) / 21.0, b1 = (6.0 + s15) / 21.0;
    const double a2 = (9.0 + 2.0 * s15) / 21.0, b2 = (6.0 - s15) / 21.0;
    const double w1 = (155.0 + s15) / 1200.0, w2 = (155.0 - s15) / 1200.0;
    TriangleRule7 r{};
    const double pts[7][3] = {{1.0 / 3, 1.0 / 3, 1.0 / 3}, {a1, b1, b1}, {b1, a1, b1}, {b1, b1, a1},
                              {a2, b2, b2},               {b2, a2, b2}, {b2, b2, a2}};
    const double w[7] = {9.0 / 40.0, w1, w1, w1, w2, w2, w2};
    for (int q = 0; q < 7; ++q) {
      for (int k = 0; k < 3; ++k) r.bary[q][k] = pts[q][k];
      r.weight[q] = w[q];
    }
    return r;
  }();
  return rule;
}

void gauss_legendre_unit(int n, std::vector<double>& nodes, std::vector<double>& weights) {
  if (n < 1) throw Error(fmt::format("Gauss-Legendre: need at least one point, got {}", n));
  nodes.assign(n, 0.0);
  weights.assign(n, 0.0);
  for (int i = 0; i < n; ++i) {
    // Newton on P_n from the Chebyshev-like initial guess; then map [-1, 1] -> [0, 1].
    double z = std::cos(M_PI * (i + 0.75) / (n + 0.5)), dp = 0;
    for (int it = 0; it < 100; ++it) {
      double p0 = 1, p1 = z;
      for (int k = 2; k <= n; ++k) {
        const double p2 = ((2 * k - 1) * z * p1 - (k - 1) * p0) / k;
        p0 = p1;
        p1 = p2;
      }
      dp = n * (z * p1 - p0) / (z * z - 1);
      const double dz = p1 / dp;
      z -= dz;
      if (std::abs(dz) < 1e-16) break;
    }
    {  // derivative at the converged node
      double p0 = 1, p1 = z;
      for (int k = 2; k <= n; ++k) {
        const double p2 = ((2 * k - 1) * z * p1 - (k - 1) * p0) / k;
        p0 = p1;
        p1 = p2;
      }
      dp = n * (z * p1 - p0) / (z * z - 1);
    }
    nodes[i] = 0.5 * (1 - z);
    weights[i] = 1.0 / ((1 - z * z) * dp * dp);  // 2 / ((1 - z^2) P'^2), halved for [0, 1]
  }
}

std::string to_string(SingleLayerQuadrature q) { return q == SingleLayerQuadrature::all7 ? "all7" : "adaptive"; }

SingleLayerQuadrature single_layer_quadrature(const std::string& name) {
  if (name == "all7") return SingleLayerQuadrature::all7;
  if (name == "adaptive") return SingleLayerQuadrature::adaptive;
  throw Error(fmt::format("single layer: unknown quadrature '{}' (all7, adaptive)", name));
}

StokesSingleLayer::StokesSingleLayer(TopologyPtr topology, SingleLayerOptions options)
    : topology_(std::move(topology)), options_(options) {
  if (options_.angular_subdivisions < 1)
    throw Error(fmt::format("single layer: angular_subdivisions must be >= 1, got {}", options_.angular_subdivisions));
  if (options_.cluster_size < 1)
    throw Error(fmt::format("single layer: cluster_size must be >= 1, got {}", options_.cluster_size));
  if (options_.far_order < 0 || options_.far_order > 4)
    throw Error(fmt::format("single layer: far_order must be in 0..4, got {}", options_.far_order));
  if (!(options_.far_ratio > 1) || !std::isfinite(options_.far_ratio))
    throw Error(fmt::format("single layer: far_ratio must be a finite number > 1, got {}", options_.far_ratio));
  gauss_legendre_unit(options_.angular_points, gl_nodes_, gl_weights_);
  const int nf = topology_->num_faces();
  const std::size_t nq = 7 * static_cast<std::size_t>(nf);
  for (auto* v : {&qx_, &qy_, &qz_, &fx_, &fy_, &fz_}) v->assign(nq, 0.0);
  slot_.resize(nf);
  std::iota(slot_.begin(), slot_.end(), 0);
  position_ = slot_;
  if (options_.quadrature == SingleLayerQuadrature::adaptive) {
    keys_.resize(nf);
    for (auto* v : {&px_, &py_, &pz_, &pfx_, &pfy_, &pfz_}) v->assign(nf, 0.0);
    const int nc = (nf + options_.cluster_size - 1) / options_.cluster_size;
    for (auto* v : {&cx_, &cy_, &cz_, &far2_}) v->assign(nc, 0.0);
  }
}

namespace {

// Integral over the triangle (x0, x1, x2), singular at x0, of f(y) . G(y, x0) dS(y), f linear with
// node values f0, f1, f2; polar coordinates about x0 (see the header).
Vec3 polar_integral(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Vec3& f0, const Vec3& f1,
                    const Vec3& f2, int subdivisions, const std::vector<double>& nodes,
                    const std::vector<double>& weights) {
  const Vec3 a = x1 - x0, b = x2 - x0;
  const double la = a.norm();
  const Vec3 t1 = a / la;
  Vec3 t2 = b - b.dot(t1) * t1;
  t2.normalize();
  // 2D coordinates in the plane: x1 -> (la, 0), x2 -> (bx, by) with by > 0.
  const double bx = b.dot(t1), by = b.dot(t2);
  const double alpha = std::atan2(by, bx);  // corner angle at x0, in (0, pi)
  const double dx = bx - la, dy = by;       // edge x1 -> x2
  Vec3 sum = Vec3::Zero();
  const double h = alpha / subdivisions;
  for (int s = 0; s < subdivisions; ++s) {
    for (std::size_t q = 0; q < nodes.size(); ++q) {
      const double phi = h * (s + nodes[q]);
      const double c = std::cos(phi), sn = std::sin(phi);
      // The ray x0 + rho (c, sn) meets the edge x1 + v (x2 - x1) at
      // rho = (a x d) / (e x d), v = -(e x a) / (e x d) (2D cross products).
      const double exd = c * dy - sn * dx;
      const double rho = (la * dy) / exd;
      const double v = (sn * la) / exd;
      const Vec3 e = c * t1 + sn * t2;
      const Vec3 fm = f0 + f1 + v * (f2 - f1);  // f(x0) + f(edge point)
      sum += (weights[q] * h * 0.5 * rho) * (fm + e.dot(fm) * e);
    }
  }
  return sum;
}

// Sum over all quadrature points y_k of the Stokeslet G(y_k, x) . f_k w_k for one target x.
// Compiled three times (AVX-512, AVX2+FMA and baseline x86-64) and picked at run time, so the
// same binary runs everywhere and uses 8- or 4-wide doubles where the processor has them. The
// file is built with -fno-math-errno (so that sqrt vectorises) and -ffp-contract=fast (FMA).
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && !defined(__SANITIZE_ADDRESS__)
__attribute__((target_clones("avx512f", "avx2,fma", "default")))
#endif
void regular_sum(double xi, double yi, double zi, const double* __restrict qx, const double* __restrict qy,
                 const double* __restrict qz, const double* __restrict fx, const double* __restrict fy,
                 const double* __restrict fz, int nq, double* out) {
  double ux = 0, uy = 0, uz = 0;
#pragma omp simd reduction(+ : ux, uy, uz)
  for (int k = 0; k < nq; ++k) {
    const double dx = qx[k] - xi, dy = qy[k] - yi, dz = qz[k] - zi;
    const double s = 1.0 / std::sqrt(dx * dx + dy * dy + dz * dz);
    const double fr = (fx[k] * dx + fy[k] * dy + fz[k] * dz) * s * s * s;
    ux += fx[k] * s + dx * fr;
    uy += fy[k] * s + dy * fr;
    uz += fz[k] * s + dz * fr;
  }
  out[0] = ux;
  out[1] = uy;
  out[2] = uz;
}

// Spreads the low 21 bits of v to every third bit (Morton interleaving).
std::uint64_t spread_bits(std::uint64_t v) {
  v &= 0x1fffff;
  v = (v | v << 32) & 0x1f00000000ffffULL;
  v = (v | v << 16) & 0x1f0000ff0000ffULL;
  v = (v | v << 8) & 0x100f00f00f00f00fULL;
  v = (v | v << 4) & 0x10c30c30c30c30c3ULL;
  v = (v | v << 2) & 0x1249249249249249ULL;
  return v;
}

// The monomials s_x^a s_y^b s_z^c, a + b + c <= order, in a fixed order.
int monomial_count(int order) { return (order + 1) * (order + 2) * (order + 3) / 6; }
void monomials(const Vec3& s, int order, double* out) {
  double px[5], py[5], pz[5];
  px[0] = py[0] = pz[0] = 1;
  for (int k = 1; k <= order; ++k) {
    px[k] = px[k - 1] * s.x();
    py[k] = py[k - 1] * s.y();
    pz[k] = pz[k - 1] * s.z();
  }
  int m = 0;
  for (int a = 0; a <= order; ++a)
    for (int b = 0; a + b <= order; ++b)
      for (int c = 0; a + b + c <= order; ++c) out[m++] = px[a] * py[b] * pz[c];
}

}  // namespace

void StokesSingleLayer::prepare(const Points& x, const Points& f) const {
  const Topology& t = *topology_;
  const int nf = t.num_faces();
  const Faces& F = t.faces();
  const TriangleRule7& rule = triangle_rule7();
  const bool adaptive = options_.quadrature == SingleLayerQuadrature::adaptive;
  if (adaptive && nf > 0) {
    // Sort the faces by the Morton key of their centroids (21 bits per axis over the bounding box).
    const Vec3 lo = x.colwise().minCoeff().transpose(), hi = x.colwise().maxCoeff().transpose();
    const double span = std::max((hi - lo).maxCoeff(), std::numeric_limits<double>::min());
    const double scale = static_cast<double>((1 << 21) - 1) / span;
    for (int tf = 0; tf < nf; ++tf) {
      const Vec3 c = (row(x, F(tf, 0)) + row(x, F(tf, 1)) + row(x, F(tf, 2))) / 3.0;
      std::uint64_t key = 0;
      for (int d = 0; d < 3; ++d) {
        double q = (c[d] - lo[d]) * scale;
        q = q >= 0 ? std::min(q, static_cast<double>((1 << 21) - 1)) : 0.0;  // also NaN -> 0
        key |= spread_bits(static_cast<std::uint64_t>(q)) << d;
      }
      keys_[tf] = key;
    }
    std::iota(slot_.begin(), slot_.end(), 0);
    std::sort(slot_.begin(), slot_.end(), [&](int a, int b) { return keys_[a] != keys_[b] ? keys_[a] < keys_[b] : a < b; });
    for (int k = 0; k < nf; ++k) position_[slot_[k]] = k;
  }

#pragma omp parallel for schedule(static)
  for (int k = 0; k < nf; ++k) {
    const int tf = slot_[k];
    const Vec3 x0 = row(x, F(tf, 0)), x1 = row(x, F(tf, 1)), x2 = row(x, F(tf, 2));
    const Vec3 f0 = row(f, F(tf, 0)), f1 = row(f, F(tf, 1)), f2 = row(f, F(tf, 2));
    const double area = 0.5 * (x1 - x0).cross(x2 - x0).norm();
    for (int q = 0; q < 7; ++q) {
      const double* l = rule.bary[q];
      const Vec3 y = l[0] * x0 + l[1] * x1 + l[2] * x2;
      const Vec3 fw = (rule.weight[q] * area) * (l[0] * f0 + l[1] * f1 + l[2] * f2);
      const std::size_t j = 7 * static_cast<std::size_t>(k) + q;
      qx_[j] = y.x(); qy_[j] = y.y(); qz_[j] = y.z();
      fx_[j] = fw.x(); fy_[j] = fw.y(); fz_[j] = fw.z();
    }
    if (adaptive) {
      const Vec3 c = (x0 + x1 + x2) / 3.0, w0 = (area / 3.0) * (f0 + f1 + f2);
      px_[k] = c.x(); py_[k] = c.y(); pz_[k] = c.z();
      pfx_[k] = w0.x(); pfy_[k] = w0.y(); pfz_[k] = w0.z();
    }
  }
  if (!adaptive) return;

  // Clusters: centre, radius, and the far rule's moment-corrected weights.
  const int cs = options_.cluster_size, nc = static_cast<int>(far2_.size());
  const int order = options_.far_order, nm = monomial_count(order);
  const double ratio2 = options_.far_ratio * options_.far_ratio;
#pragma omp parallel for schedule(dynamic, 1)
  for (int c = 0; c < nc; ++c) {
    const int k0 = c * cs, k1 = std::min(nf, k0 + cs), n = k1 - k0;
    Vec3 centre = Vec3::Zero();
    for (int k = k0; k < k1; ++k) centre += Vec3(px_[k], py_[k], pz_[k]);
    centre /= n;
    double rho2 = 0;
    for (int k = k0; k < k1; ++k)
      for (int d = 0; d < 3; ++d) rho2 = std::max(rho2, (row(x, F(slot_[k], d)) - centre).squaredNorm());
    cx_[c] = centre.x(); cy_[c] = centre.y(); cz_[c] = centre.z();
    if (n < nm || !(rho2 > 0)) {  // too few points to match the moments: always the 7-point rule
      far2_[c] = std::numeric_limits<double>::infinity();
      continue;
    }
    far2_[c] = ratio2 * rho2;
    const double inv_rho = 1.0 / std::sqrt(rho2);
    // Residual moments R = sum_k m(s_k) w_k f_k - sum_t m(s_t) W0_t (nm x 3), proxies' V (nm x n).
    Eigen::MatrixXd V(nm, n), R = Eigen::MatrixXd::Zero(nm, 3);
    double m[35];
    for (int k = k0; k < k1; ++k) {
      for (int q = 0; q < 7; ++q) {
        const std::size_t j = 7 * static_cast<std::size_t>(k) + q;
        monomials((Vec3(qx_[j], qy_[j], qz_[j]) - centre) * inv_rho, order, m);
        for (int r = 0; r < nm; ++r) {
          R(r, 0) += m[r] * fx_[j];
          R(r, 1) += m[r] * fy_[j];
          R(r, 2) += m[r] * fz_[j];
        }
      }
      monomials((Vec3(px_[k], py_[k], pz_[k]) - centre) * inv_rho, order, m);
      for (int r = 0; r < nm; ++r) {
        V(r, k - k0) = m[r];
        R(r, 0) -= m[r] * pfx_[k];
        R(r, 1) -= m[r] * pfy_[k];
        R(r, 2) -= m[r] * pfz_[k];
      }
    }
    // Least-norm correction; directions the centroids cannot resolve (a flat cluster has no
    // moments across its plane) are left alone: their source moments vanish to rounding too.
    Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> cod;
    cod.setThreshold(1e-8);
    cod.compute(V);
    const Eigen::MatrixXd dW = cod.solve(R);
    for (int k = k0; k < k1; ++k) {
      pfx_[k] += dW(k - k0, 0);
      pfy_[k] += dW(k - k0, 1);
      pfz_[k] += dW(k - k0, 2);
    }
  }
}

void StokesSingleLayer::velocity(const Points& x, const Points& f, double mu, Points& u) const {
  const Topology& t = *topology_;
  const int nv = t.num_vertices(), nf = t.num_faces();
  if (x.rows() != nv || f.rows() != nv)
    throw Error(fmt::format("single layer: {} positions and {} densities for {} vertices", x.rows(), f.rows(), nv));
  if (u.rows() != nv) u.resize(nv, 3);
  const Faces& F = t.faces();
  prepare(x, f);

  const bool adaptive = options_.quadrature == SingleLayerQuadrature::adaptive;
  const int nq = 7 * nf;
  const double* qx = qx_.data(); const double* qy = qy_.data(); const double* qz = qz_.data();
  const double* fx = fx_.data(); const double* fy = fy_.data(); const double* fz = fz_.data();
  const double* px = px_.data(); const double* py = py_.data(); const double* pz = pz_.data();
  const double* pfx = pfx_.data(); const double* pfy = pfy_.data(); const double* pfz = pfz_.data();
  const int cs = options_.cluster_size, nc = static_cast<int>(far2_.size());
  const auto& rf = t.ring_faces();
  const auto& rc = t.ring_corners();
  const double scale = 1.0 / (8.0 * M_PI * mu);

#pragma omp parallel for schedule(static)
  for (int i = 0; i < nv; ++i) {
    const double xi = x(i, 0), yi = x(i, 1), zi = x(i, 2);
    // The regular rule over every triangle (the hot loop).
    double ux = 0, uy = 0, uz = 0, acc[3];
    if (!adaptive) {
      regular_sum(xi, yi, zi, qx, qy, qz, fx, fy, fz, nq, acc);
      ux = acc[0], uy = acc[1], uz = acc[2];
    } else {
      for (int c = 0; c < nc; ++c) {
        const double dx = cx_[c] - xi, dy = cy_[c] - yi, dz = cz_[c] - zi;
        const int k0 = c * cs, n = std::min(nf, k0 + cs) - k0;
        if (dx * dx + dy * dy + dz * dz >= far2_[c])
          regular_sum(xi, yi, zi, px + k0, py + k0, pz + k0, pfx + k0, pfy + k0, pfz + k0, n, acc);
        else
          regular_sum(xi, yi, zi, qx + 7 * k0, qy + 7 * k0, qz + 7 * k0, fx + 7 * k0, fy + 7 * k0, fz + 7 * k0,
                      7 * n, acc);
        ux += acc[0], uy += acc[1], uz += acc[2];
      }
    }
    // The triangles at node i (always on the 7-point rule, see the header): take back what the
    // regular rule added, add the polar integral.
    Vec3 corr = Vec3::Zero();
    const Vec3 xv(xi, yi, zi);
    for (int r = t.ring_begin(i); r < t.ring_end(i); ++r) {
      const int tf = rf[r], c = rc[r];
      for (int q = 0; q < 7; ++q) {
        const int k = 7 * position_[tf] + q;
        const Vec3 d(qx[k] - xi, qy[k] - yi, qz[k] - zi), fw(fx[k], fy[k], fz[k]);
        const double s = 1.0 / d.norm();
        corr -= fw * s + d * (fw.dot(d) * s * s * s);
      }
      const int j = F(tf, (c + 1) % 3), l = F(tf, (c + 2) % 3);
      corr += polar_integral(xv, row(x, j), row(x, l), row(f, i), row(f, j), row(f, l),
                             options_.angular_subdivisions, gl_nodes_, gl_weights_);
    }
    u(i, 0) = scale * (ux + corr.x());
    u(i, 1) = scale * (uy + corr.y());
    u(i, 2) = scale * (uz + corr.z());
  }
}

}  // namespace bendlab
