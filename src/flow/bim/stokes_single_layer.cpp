#include "bendlab/flow/bim/stokes_single_layer.hpp"

#include "bendlab/flow/bim/chebyshev_moments.hpp"

#include <fmt/format.h>

#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <numeric>
#include <utility>

namespace bendlab {

namespace {
// tree_mixed: the kernel sums blocks of this many points (one AVX-512 register of floats, two of
// AVX2), every range padded to whole blocks.
constexpr int kMixedBlock = 16;
}  // namespace

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

std::string to_string(SingleLayerQuadrature q) {
  switch (q) {
    case SingleLayerQuadrature::all7: return "all7";
    case SingleLayerQuadrature::adaptive: return "adaptive";
    case SingleLayerQuadrature::tree: return "tree";
    case SingleLayerQuadrature::tree_mixed: return "tree-mixed";
  }
  return "unknown";
}

SingleLayerQuadrature single_layer_quadrature(const std::string& name) {
  if (name == "all7") return SingleLayerQuadrature::all7;
  if (name == "adaptive") return SingleLayerQuadrature::adaptive;
  if (name == "tree") return SingleLayerQuadrature::tree;
  if (name == "tree-mixed") return SingleLayerQuadrature::tree_mixed;
  throw Error(fmt::format("single layer: unknown quadrature '{}' (all7, adaptive, tree, tree-mixed)", name));
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
  if (options_.tree_leaf_size < 1)
    throw Error(fmt::format("single layer: tree_leaf_size must be >= 1, got {}", options_.tree_leaf_size));
  if (options_.tree_order < 0 || options_.tree_order > 8)
    throw Error(fmt::format("single layer: tree_order must be in 0..8, got {}", options_.tree_order));
  if (!(options_.tree_ratio > 1) || !std::isfinite(options_.tree_ratio))
    throw Error(fmt::format("single layer: tree_ratio must be a finite number > 1, got {}", options_.tree_ratio));
  if (!(options_.tree_tolerance >= 0) || !std::isfinite(options_.tree_tolerance))
    throw Error(fmt::format("single layer: tree_tolerance must be a finite number >= 0, got {}", options_.tree_tolerance));
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
  if (tree() && nf > 0) {
    keys_.resize(nf);
    // Halve the sorted range until a cluster holds at most tree_leaf_size faces, breadth first.
    std::vector<int> depth{0};
    tree_begin_ = {0};
    tree_end_ = {nf};
    tree_child_ = {-1};
    for (std::size_t j = 0; j < tree_begin_.size(); ++j) {
      const int b = tree_begin_[j], e = tree_end_[j];
      if (e - b <= options_.tree_leaf_size) continue;
      const int mid = b + (e - b) / 2;
      tree_child_[j] = static_cast<int>(tree_begin_.size());
      for (const auto& [cb, ce] : {std::pair{b, mid}, std::pair{mid, e}}) {
        tree_begin_.push_back(cb);
        tree_end_.push_back(ce);
        tree_child_.push_back(-1);
        depth.push_back(depth[j] + 1);
      }
    }
    const int nn = static_cast<int>(tree_begin_.size());
    for (int j = 0; j < nn; ++j)
      if (j == 0 || depth[j] != depth[j - 1]) tree_level_.push_back(j);
    tree_level_.push_back(nn);
    // Proxy slots for the clusters with more 7-point points than proxies.
    const int q = options_.tree_order, nm = (q + 1) * (q + 2) * (q + 3) / 6, padded = (nm + 7) / 8 * 8;
    int proxies = 0;
    tree_proxy_.assign(nn, -1);
    for (int j = 0; j < nn; ++j)
      if (7 * (tree_end_[j] - tree_begin_[j]) >= 2 * padded) tree_proxy_[j] = proxies++;
    tree_count_.assign(nn, 0);
    for (auto* v : {&bcx_, &bcy_, &bcz_, &tree_far2_}) v->assign(nn, 0.0);
    for (auto* v : {&tpx_, &tpy_, &tpz_, &tfx_, &tfy_, &tfz_})
      v->assign(static_cast<std::size_t>(proxies) * padded, 0.0);
    if (options_.quadrature == SingleLayerQuadrature::tree_mixed) {
      // One range per leaf (its 7-point points) and per proxy slot, each a whole number of blocks.
      auto blocks = [](int n) { return (n + kMixedBlock - 1) / kMixedBlock * kMixedBlock; };
      mixed_proxy_count_ = blocks(padded);
      mixed_leaf_.assign(nn, -1);
      mixed_leaf_count_.assign(nn, 0);
      mixed_proxy_.assign(nn, -1);
      int size = 0;
      for (int j = 0; j < nn; ++j) {
        if (tree_child_[j] < 0) {
          mixed_leaf_[j] = size;
          mixed_leaf_count_[j] = blocks(7 * (tree_end_[j] - tree_begin_[j]));
          size += mixed_leaf_count_[j];
        }
        if (tree_proxy_[j] >= 0) {
          mixed_proxy_[j] = size;
          size += mixed_proxy_count_;
        }
      }
      // Zero: the padding keeps zero weights (and, for proxies, the box centre) from here on.
      for (auto* v : {&mx_, &my_, &mz_, &mfx_, &mfy_, &mfz_}) v->assign(size, 0.0f);
    }
    // The basis T_a(s_x) T_b(s_y) T_c(s_z), a + b + c <= q, and the reference points in
    // [-1, 1]^3: approximate Fekete points, the first nm columns that column-pivoted QR picks
    // from the basis evaluated on the tensor grid of q + 3 Chebyshev nodes per axis.
    for (int a = 0; a <= q; ++a)
      for (int b = 0; a + b <= q; ++b)
        for (int c = 0; a + b + c <= q; ++c) tree_basis_.insert(tree_basis_.end(), {a, b, c});
    const int ng = q + 3, ncand = ng * ng * ng;
    std::vector<double> node(ng);
    for (int a = 0; a < ng; ++a) node[a] = std::cos(M_PI * (2 * a + 1) / (2.0 * ng));
    auto chebyshev = [&](const Vec3& s, int m) {
      double v = 1;
      for (int d = 0; d < 3; ++d) v *= std::cos(tree_basis_[3 * m + d] * std::acos(std::clamp(s[d], -1.0, 1.0)));
      return v;
    };
    Eigen::MatrixXd B(nm, ncand);
    std::vector<Vec3> cand(ncand);
    for (int c = 0; c < ncand; ++c) {
      cand[c] = Vec3(node[c / (ng * ng)], node[(c / ng) % ng], node[c % ng]);
      for (int m = 0; m < nm; ++m) B(m, c) = chebyshev(cand[c], m);
    }
    const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(B);
    Eigen::MatrixXd V(nm, nm);  // V(l, beta) = T_beta(p_l)
    tree_reference_.resize(3 * nm);
    for (int l = 0; l < nm; ++l) {
      const Vec3 p = cand[qr.colsPermutation().indices()[l]];
      for (int d = 0; d < 3; ++d) tree_reference_[3 * l + d] = p[d];
      for (int m = 0; m < nm; ++m) V(l, m) = chebyshev(p, m);
    }
    const Eigen::MatrixXd Cm = V.fullPivLu().inverse();  // L_m(s) = sum_beta T_beta(s) C(beta, m)
    tree_lagrange_.resize(static_cast<std::size_t>(nm) * nm);
    for (int beta = 0; beta < nm; ++beta)
      for (int m = 0; m < nm; ++m) tree_lagrange_[beta * nm + m] = Cm(beta, m);
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

// One Stokeslet term G(y, x) . F added to (ux, uy, uz): (dx, dy, dz) = y - x and (fx, fy, fz) =
// F, the density times the quadrature weight, in the precision Real (double; float for
// tree_mixed, see the header). Inlined into the kernels below, each compiled three times
// (AVX-512, AVX2+FMA and baseline x86-64) and picked at run time, so the same binary runs
// everywhere and uses 8- or 4-wide doubles (16 or 8 floats) where the processor has them. The
// file is built with -fno-math-errno (so that sqrt vectorises) and -ffp-contract=fast (FMA).
template <typename Real>
[[gnu::always_inline]] inline void add_stokeslet(Real dx, Real dy, Real dz, Real fx, Real fy, Real fz, Real& ux,
                                                 Real& uy, Real& uz) {
  const Real s = Real(1) / std::sqrt(dx * dx + dy * dy + dz * dz);
  const Real fr = (fx * dx + fy * dy + fz * dz) * s * s * s;
  ux += fx * s + dx * fr;
  uy += fy * s + dy * fr;
  uz += fz * s + dz * fr;
}

// Sum over the quadrature points y_k, k < nq, of the Stokeslet G(y_k, x) . f_k w_k for one target x.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && !defined(__SANITIZE_ADDRESS__)
__attribute__((target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default")))
#endif
void regular_sum(double xi, double yi, double zi, const double* __restrict qx, const double* __restrict qy,
                 const double* __restrict qz, const double* __restrict fx, const double* __restrict fy,
                 const double* __restrict fz, int nq, double* out) {
  double ux = 0, uy = 0, uz = 0;
#pragma omp simd reduction(+ : ux, uy, uz)
  for (int k = 0; k < nq; ++k) add_stokeslet(qx[k] - xi, qy[k] - yi, qz[k] - zi, fx[k], fy[k], fz[k], ux, uy, uz);
  out[0] = ux;
  out[1] = uy;
  out[2] = uz;
}

// tree_mixed: one target against a list of ranges of the single-precision arrays (a near leaf's
// 7-point points or a far cluster's proxies), each range's points relative to its box centre and
// (ox, oy, oz) the target's offset from that centre. Each range is summed in float in kMixedBlock
// partial sums (one vector register of floats with AVX-512, two with AVX2), which are then added
// to partial sums in double; the double lanes are added up once per target. Every range is a
// whole number of blocks (zero weights pad it), so the loop has no remainder.
struct MixedRange {
  int start, count;
  float ox, oy, oz;
};
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && !defined(__SANITIZE_ADDRESS__)
__attribute__((target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default")))
#endif
void mixed_sums(const MixedRange* ranges, int nranges, const float* __restrict qx, const float* __restrict qy,
                const float* __restrict qz, const float* __restrict fx, const float* __restrict fy,
                const float* __restrict fz, double* out) {
  constexpr int L = kMixedBlock;
  double sx[L] = {}, sy[L] = {}, sz[L] = {};
  for (int r = 0; r < nranges; ++r) {
    const float xi = ranges[r].ox, yi = ranges[r].oy, zi = ranges[r].oz;
    float ax[L] = {}, ay[L] = {}, az[L] = {};
    // 64-bit indices: with 32-bit ones the vectoriser may pick narrower registers.
    const std::int64_t k1 = static_cast<std::int64_t>(ranges[r].start) + ranges[r].count;
    for (std::int64_t k0 = ranges[r].start; k0 < k1; k0 += L) {
#pragma omp simd
      for (std::int64_t l = 0; l < L; ++l) {
        const std::int64_t k = k0 + l;
        add_stokeslet(qx[k] - xi, qy[k] - yi, qz[k] - zi, fx[k], fy[k], fz[k], ax[l], ay[l], az[l]);
      }
    }
#pragma omp simd
    for (int l = 0; l < L; ++l) {
      sx[l] += ax[l];
      sy[l] += ay[l];
      sz[l] += az[l];
    }
  }
  double ux = 0, uy = 0, uz = 0;
  for (int l = 0; l < L; ++l) ux += sx[l], uy += sy[l], uz += sz[l];
  out[0] = ux;
  out[1] = uy;
  out[2] = uz;
}

// Proxy weights W_m = sum_beta C(beta, m) M_beta for m < nm (C row-major nm x nm), zero up to padded.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && !defined(__SANITIZE_ADDRESS__)
__attribute__((target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default")))
#endif
void lagrange_weights(const double* C, const double* mx, const double* my, const double* mz, int nm, int padded,
                      double* __restrict wx, double* __restrict wy, double* __restrict wz) {
  for (int m = 0; m < padded; ++m) wx[m] = wy[m] = wz[m] = 0;
  for (int beta = 0; beta < nm; ++beta) {
    const double* c = C + static_cast<std::size_t>(beta) * nm;
    const double ax = mx[beta], ay = my[beta], az = mz[beta];
#pragma omp simd
    for (int m = 0; m < nm; ++m) {
      wx[m] += c[m] * ax;
      wy[m] += c[m] * ay;
      wz[m] += c[m] * az;
    }
  }
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
  const bool tree = this->tree();
  if ((adaptive || tree) && nf > 0) {
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
    if (tree) {
      // k-d refinement, top down: each cluster's faces are split at the median centroid along the
      // widest extent of their centroids, so that both children are compact (Morton ranges can
      // jump across the surface).
      std::vector<Vec3> centroid(nf);
      for (int tf = 0; tf < nf; ++tf) centroid[tf] = (row(x, F(tf, 0)) + row(x, F(tf, 1)) + row(x, F(tf, 2))) / 3.0;
      for (std::size_t j = 0; j < tree_begin_.size(); ++j) {
        const int child = tree_child_[j];
        if (child < 0) continue;
        const int b = tree_begin_[j], e = tree_end_[j], mid = tree_end_[child];
        Vec3 clo = Vec3::Constant(std::numeric_limits<double>::infinity()), chi = -clo;
        for (int k = b; k < e; ++k) {
          clo = clo.cwiseMin(centroid[slot_[k]]);
          chi = chi.cwiseMax(centroid[slot_[k]]);
        }
        int axis = 0;
        (chi - clo).maxCoeff(&axis);
        std::nth_element(slot_.begin() + b, slot_.begin() + mid, slot_.begin() + e, [&](int p, int r) {
          const double cp = centroid[p][axis], cr = centroid[r][axis];
          return cp != cr ? cp < cr : p < r;
        });
      }
    }
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
  if (tree && nf > 0) prepare_tree(x);
  if (tree && nf > 0 && options_.quadrature == SingleLayerQuadrature::tree_mixed) prepare_single_precision();
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

void StokesSingleLayer::prepare_tree(const Points& x) const {
  const Faces& F = topology_->faces();
  const int q = options_.tree_order, nm = static_cast<int>(tree_basis_.size()) / 3;
  const int padded = (nm + 7) / 8 * 8;
  const double ratio = options_.tree_ratio;
  const int levels = static_cast<int>(tree_level_.size()) - 1;
  // Scale of the velocity: sum_k |F_k| over all 7-point points over the surface's half diagonal.
  const std::size_t nq = qx_.size();
  std::vector<double> strength(tree_begin_.size());
  double total = 0;
  for (std::size_t k = 0; k < nq; ++k) total += std::sqrt(fx_[k] * fx_[k] + fy_[k] * fy_[k] + fz_[k] * fz_[k]);
  const double span = 0.5 * (x.colwise().maxCoeff() - x.colwise().minCoeff()).norm();
  const double budget = options_.tree_tolerance * total / span;
  auto process = [&](int j) {  // box, acceptance distance and proxies of cluster j, its children done
    const int b = tree_begin_[j], e = tree_end_[j];
    // The box of the cluster's triangle corners along their principal axes: it holds every
    // 7-point point and every proxy of the cluster, and every node on its triangles.
    Vec3 mean = Vec3::Zero();
    for (int k = b; k < e; ++k)
      for (int d = 0; d < 3; ++d) mean += row(x, F(slot_[k], d));
    mean /= 3.0 * (e - b);
    Mat3 cov = Mat3::Zero();
    for (int k = b; k < e; ++k)
      for (int d = 0; d < 3; ++d) {
        const Vec3 r = row(x, F(slot_[k], d)) - mean;
        cov += r * r.transpose();
      }
    Mat3 R = Mat3::Identity();
    if (cov.allFinite()) {
      const Eigen::SelfAdjointEigenSolver<Mat3> es(cov);
      if (es.info() == Eigen::Success) R = es.eigenvectors();
    }
    Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
    for (int k = b; k < e; ++k)
      for (int d = 0; d < 3; ++d) {
        const Vec3 s = R.transpose() * (row(x, F(slot_[k], d)) - mean);
        lo = lo.cwiseMin(s);
        hi = hi.cwiseMax(s);
      }
    const Vec3 centre = mean + R * (0.5 * (lo + hi)), h = 0.5 * (hi - lo);
    bcx_[j] = centre.x(); bcy_[j] = centre.y(); bcz_[j] = centre.z();
    const double rho2 = h.squaredNorm();
    // A point-like or non-finite box is never far (its faces keep the 7-point rule).
    const bool usable = rho2 > 0 && std::isfinite(rho2);
    // Far: at least tree_ratio box half diagonals away, and where the far field's error estimate
    // A_j (rho / d)^(q + 1) / d (A_j = sum |F_k| over the cluster) is below the budget.
    double a = 0;
    if (tree_child_[j] < 0) {
      for (std::size_t k = 7 * static_cast<std::size_t>(b); k < 7 * static_cast<std::size_t>(e); ++k)
        a += std::sqrt(fx_[k] * fx_[k] + fy_[k] * fy_[k] + fz_[k] * fz_[k]);
    } else {
      a = strength[tree_child_[j]] + strength[tree_child_[j] + 1];
    }
    strength[j] = a;
    double dmin = ratio * std::sqrt(rho2);
    if (budget > 0) dmin = std::max(dmin, std::pow(a * std::pow(rho2, 0.5 * (q + 1)) / budget, 1.0 / (q + 2)));
    tree_far2_[j] = usable ? dmin * dmin : std::numeric_limits<double>::infinity();
    tree_count_[j] = 0;
    // Proxies only where they are at most half as many as the 7-point points; elsewhere the
    // exact rule costs little more.
    if (!usable || tree_proxy_[j] < 0 || 2 * padded > 7 * (e - b)) return;
    tree_count_[j] = padded;
    // Chebyshev moments M_beta = sum_k T_beta(s_k) F_k, |beta| <= q, of the cluster's sources
    // k, s_k their coordinates in the box scaled to [-1, 1]^3: the 7-point points of a leaf or
    // of a child without proxies, and the proxies of a child with them (they carry the child's
    // moments of degree <= q exactly, and a polynomial of degree <= q in the parent's box is
    // one in the child's).
    Vec3 inv_h;
    for (int d = 0; d < 3; ++d) inv_h[d] = h[d] > 1e-12 * std::sqrt(rho2) ? 1.0 / h[d] : 0.0;
    const Mat3 S = inv_h.asDiagonal() * R.transpose();
    double M[3][165] = {};
    auto add = [&](const double* sx, const double* sy, const double* sz, const double* sfx, const double* sfy,
                   const double* sfz, int count) {
      chebyshev_moments(S.data(), centre.data(), q, sx, sy, sz, sfx, sfy, sfz, count, M[0], M[1], M[2]);
    };
    auto add_points = [&](int kb, int ke) {
      const std::size_t o = 7 * static_cast<std::size_t>(kb);
      add(qx_.data() + o, qy_.data() + o, qz_.data() + o, fx_.data() + o, fy_.data() + o, fz_.data() + o,
          7 * (ke - kb));
    };
    const int child = tree_child_[j];
    if (child < 0) {
      add_points(b, e);
    } else {
      for (int c = child; c < child + 2; ++c) {
        if (tree_count_[c] == 0) {
          add_points(tree_begin_[c], tree_end_[c]);
        } else {
          const std::size_t o = static_cast<std::size_t>(tree_proxy_[c]) * padded;
          add(tpx_.data() + o, tpy_.data() + o, tpz_.data() + o, tfx_.data() + o, tfy_.data() + o,
              tfz_.data() + o, tree_count_[c]);
        }
      }
    }
    // Proxies: the reference points in the box, weights W_m = sum_beta C(beta, m) M_beta (the
    // Lagrange basis of degree q at the reference points in the Chebyshev basis); the padding
    // carries zero weights at the centre.
    const std::size_t o = static_cast<std::size_t>(tree_proxy_[j]) * padded;
    const double* C = tree_lagrange_.data();
    for (int m = 0; m < padded; ++m) {
      Vec3 p = centre;
      if (m < nm)
        p += R * Vec3(h[0] * tree_reference_[3 * m], h[1] * tree_reference_[3 * m + 1],
                      h[2] * tree_reference_[3 * m + 2]);
      tpx_[o + m] = p.x(); tpy_[o + m] = p.y(); tpz_[o + m] = p.z();
    }
    lagrange_weights(C, M[0], M[1], M[2], nm, padded, tfx_.data() + o, tfy_.data() + o, tfz_.data() + o);
  };
  // Children before parents, in one parallel region: the subtrees below depth `split` each on one
  // thread (bottom up, that is in decreasing breadth-first index), then the top levels in order.
  const int split = std::min(levels - 1, 5);
#pragma omp parallel for schedule(dynamic, 1)
  for (int r = tree_level_[split]; r < tree_level_[split + 1]; ++r) {
    std::vector<int> nodes{r};
    for (std::size_t k = 0; k < nodes.size(); ++k)
      if (tree_child_[nodes[k]] >= 0) nodes.insert(nodes.end(), {tree_child_[nodes[k]], tree_child_[nodes[k]] + 1});
    std::sort(nodes.begin(), nodes.end(), std::greater<int>());
    for (const int j : nodes) process(j);
  }
  for (int j = tree_level_[split] - 1; j >= 0; --j) process(j);
}

namespace {
// Points (x, y, z) and weights (fx, fy, fz) at [b, e) to the single-precision arrays from o on,
// the points relative to c.
using Doubles = std::vector<double>;
using Floats = std::vector<float>;
void to_single(const Doubles& x, const Doubles& y, const Doubles& z, const Doubles& fx, const Doubles& fy,
               const Doubles& fz, std::size_t b, std::size_t e, const std::array<double, 3>& c, std::size_t o,
               Floats& sx, Floats& sy, Floats& sz, Floats& sfx, Floats& sfy, Floats& sfz) {
  for (std::size_t k = b; k < e; ++k) {
    const std::size_t m = k - b + o;
    sx[m] = static_cast<float>(x[k] - c[0]);
    sy[m] = static_cast<float>(y[k] - c[1]);
    sz[m] = static_cast<float>(z[k] - c[2]);
    sfx[m] = static_cast<float>(fx[k]);
    sfy[m] = static_cast<float>(fy[k]);
    sfz[m] = static_cast<float>(fz[k]);
  }
}
}  // namespace

void StokesSingleLayer::prepare_single_precision() const {
  const int nn = static_cast<int>(tree_begin_.size());
#pragma omp parallel for schedule(static)
  for (int j = 0; j < nn; ++j) {
    // A leaf's 7-point points and a cluster's proxies relative to the box centre; weights as they are.
    const std::array<double, 3> centre{bcx_[j], bcy_[j], bcz_[j]};
    if (mixed_leaf_[j] >= 0) {
      const std::size_t b = 7 * static_cast<std::size_t>(tree_begin_[j]), e = 7 * static_cast<std::size_t>(tree_end_[j]);
      const std::size_t o = mixed_leaf_[j];
      to_single(qx_, qy_, qz_, fx_, fy_, fz_, b, e, centre, o, mx_, my_, mz_, mfx_, mfy_, mfz_);
      // The padding: zero weights at the leaf's first point, which is never at a node (a node
      // may sit at the box centre, where the kernel is infinite and zero times it not a number).
      for (std::size_t k = o + (e - b); k < o + mixed_leaf_count_[j]; ++k) {
        mx_[k] = mx_[o], my_[k] = my_[o], mz_[k] = mz_[o];
        mfx_[k] = mfy_[k] = mfz_[k] = 0.0f;
      }
    }
    if (tree_count_[j] > 0) {
      // The padding past tree_count_ keeps its zero weights at the centre: proxies are summed
      // only for targets at least tree_ratio box radii away.
      const std::size_t b = static_cast<std::size_t>(tree_proxy_[j]) * tree_count_[j], e = b + tree_count_[j];
      to_single(tpx_, tpy_, tpz_, tfx_, tfy_, tfz_, b, e, centre, mixed_proxy_[j], mx_, my_, mz_, mfx_, mfy_, mfz_);
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
  const bool tree = this->tree() && nf > 0;
  const bool single = tree && options_.quadrature == SingleLayerQuadrature::tree_mixed;
  const int nq = 7 * nf;
  const double* qx = qx_.data(); const double* qy = qy_.data(); const double* qz = qz_.data();
  const double* fx = fx_.data(); const double* fy = fy_.data(); const double* fz = fz_.data();
  const double* px = px_.data(); const double* py = py_.data(); const double* pz = pz_.data();
  const double* pfx = pfx_.data(); const double* pfy = pfy_.data(); const double* pfz = pfz_.data();
  const int cs = options_.cluster_size, nc = static_cast<int>(far2_.size());
  const auto& rf = t.ring_faces();
  const auto& rc = t.ring_corners();
  const double scale = 1.0 / (8.0 * M_PI * mu);

#pragma omp parallel
  {
  // tree_mixed: the ranges of one target (each cluster gives at most one).
  std::vector<MixedRange> ranges(single ? tree_begin_.size() : 0);
#pragma omp for schedule(static)
  for (int i = 0; i < nv; ++i) {
    const double xi = x(i, 0), yi = x(i, 1), zi = x(i, 2);
    // The regular rule over every triangle (the hot loop).
    double ux = 0, uy = 0, uz = 0, acc[3];
    if (single) {
      // As the tree below, each near leaf and each far cluster a range of its own, summed in
      // single precision relative to its box centre (a far cluster without proxies by its leaves).
      int stack[128], top = 0, nranges = 0;
      stack[top++] = 0;
      while (top > 0) {
        const int j = stack[--top];
        const double dx = bcx_[j] - xi, dy = bcy_[j] - yi, dz = bcz_[j] - zi;
        const bool far = dx * dx + dy * dy + dz * dz >= tree_far2_[j];
        int start = -1, count = 0;
        if (far && tree_count_[j] > 0) {
          start = mixed_proxy_[j], count = mixed_proxy_count_;
        } else if (tree_child_[j] < 0) {
          start = mixed_leaf_[j], count = mixed_leaf_count_[j];
        } else {
          stack[top++] = tree_child_[j] + 1;
          stack[top++] = tree_child_[j];
          continue;
        }
        ranges[nranges++] = {start, count, static_cast<float>(-dx), static_cast<float>(-dy), static_cast<float>(-dz)};
      }
      mixed_sums(ranges.data(), nranges, mx_.data(), my_.data(), mz_.data(), mfx_.data(), mfy_.data(), mfz_.data(),
                 acc);
      ux = acc[0], uy = acc[1], uz = acc[2];
    } else if (tree) {
      // Top down from the root: a far cluster by its proxies (or its 7-point points where it has
      // none), a near one by its children, a near leaf by its 7-point points. Faces taken
      // directly come in sorted order; consecutive ranges are summed in one call.
      int stack[128], top = 0, a = 0, b = 0;
      stack[top++] = 0;
      auto flush = [&] {
        if (b > a) {
          regular_sum(xi, yi, zi, qx + 7 * a, qy + 7 * a, qz + 7 * a, fx + 7 * a, fy + 7 * a, fz + 7 * a,
                      7 * (b - a), acc);
          ux += acc[0], uy += acc[1], uz += acc[2];
        }
      };
      while (top > 0) {
        const int j = stack[--top];
        const double dx = bcx_[j] - xi, dy = bcy_[j] - yi, dz = bcz_[j] - zi;
        const bool far = dx * dx + dy * dy + dz * dz >= tree_far2_[j];
        if (far && tree_count_[j] > 0) {
          const std::size_t o = static_cast<std::size_t>(tree_proxy_[j]) * tree_count_[j];
          regular_sum(xi, yi, zi, tpx_.data() + o, tpy_.data() + o, tpz_.data() + o, tfx_.data() + o,
                      tfy_.data() + o, tfz_.data() + o, tree_count_[j], acc);
          ux += acc[0], uy += acc[1], uz += acc[2];
        } else if (far || tree_child_[j] < 0) {
          if (tree_begin_[j] != b) {
            flush();
            a = tree_begin_[j];
          }
          b = tree_end_[j];
        } else {
          stack[top++] = tree_child_[j] + 1;
          stack[top++] = tree_child_[j];
        }
      }
      flush();
    } else if (!adaptive) {
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
}

}  // namespace bendlab
