// The tree rule of the single layer (stokes_single_layer.hpp, quadrature tree and tree-mixed):
// the cluster tree over the faces, its k-d refinement of the Morton order at each evaluation,
// the boxes and Chebyshev proxies of the clusters, and the traversal that sums a target's far
// clusters by their proxies and its near leaves by their 7-point points. Built with
// -fno-math-errno -ffp-contract=fast (CMakeLists.txt), as the rest of the single layer.
#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <utility>

#include "bendlab/flow/bim/chebyshev_moments.hpp"
#include "bendlab/flow/bim/stokes_single_layer.hpp"
#include "bendlab/flow/bim/stokeslet_sums.hpp"

namespace bendlab {

namespace {

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

}  // namespace

void StokesSingleLayer::build_tree() {
  const int nf = topology_->num_faces();
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

void StokesSingleLayer::refine_tree_order(const Points& x) const {
  const int nf = topology_->num_faces();
  const Faces& F = topology_->faces();
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

void StokesSingleLayer::tree_sum(double xi, double yi, double zi, double* u) const {
  const double* qx = qx_.data(); const double* qy = qy_.data(); const double* qz = qz_.data();
  const double* fx = fx_.data(); const double* fy = fy_.data(); const double* fz = fz_.data();
  double ux = 0, uy = 0, uz = 0, acc[3];
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
  u[0] = ux;
  u[1] = uy;
  u[2] = uz;
}

}  // namespace bendlab
