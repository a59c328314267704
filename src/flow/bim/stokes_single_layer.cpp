// The single layer's options, the 7-point points and weighted densities of an evaluation (faces
// in Morton order for the adaptive and tree rules), and velocity(): each target's regular sum by
// its rule, then its own triangles taken back and integrated in polar coordinates. Built with
// -fno-math-errno -ffp-contract=fast (CMakeLists.txt), as every file of the single layer.
#include "bendlab/flow/bim/stokes_single_layer.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <utility>

#include "bendlab/flow/bim/singular_polar_integral.hpp"
#include "bendlab/flow/bim/stokeslet_sums.hpp"

namespace bendlab {

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
    build_tree();
    if (options_.quadrature == SingleLayerQuadrature::tree_mixed) layout_single_precision();
  }
}

namespace {

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
    if (tree) refine_tree_order(x);
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
  if (adaptive) prepare_adaptive(x);
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
    // The regular rule over every triangle (the hot loop): its sum at the target.
    double regular[3];
    if (single)
      mixed_sum(xi, yi, zi, ranges, regular);
    else if (tree)
      tree_sum(xi, yi, zi, regular);
    else if (!adaptive)
      regular_sum(xi, yi, zi, qx, qy, qz, fx, fy, fz, nq, regular);
    else
      adaptive_sum(xi, yi, zi, regular);
    const double ux = regular[0], uy = regular[1], uz = regular[2];
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
      corr += singular_polar_integral(xv, row(x, j), row(x, l), row(f, i), row(f, j), row(f, l),
                                      options_.angular_subdivisions, gl_nodes_, gl_weights_);
    }
    u(i, 0) = scale * (ux + corr.x());
    u(i, 1) = scale * (uy + corr.y());
    u(i, 2) = scale * (uz + corr.z());
  }
  }
}

}  // namespace bendlab
