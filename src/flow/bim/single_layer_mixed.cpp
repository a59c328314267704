// The single-precision tree (stokes_single_layer.hpp, quadrature tree-mixed): where each leaf's
// 7-point points and each cluster's proxies lie in the float arrays (padded to whole blocks of
// mixed_sums), their copies relative to the box centres at each evaluation, and the traversal
// that lists a target's ranges for mixed_sums (stokeslet_sums.hpp). Built with -fno-math-errno
// -ffp-contract=fast (CMakeLists.txt), as the rest of the single layer.
#include <array>

#include "bendlab/flow/bim/stokes_single_layer.hpp"
#include "bendlab/flow/bim/stokeslet_sums.hpp"

namespace bendlab {

void StokesSingleLayer::layout_single_precision() {
  const int nn = static_cast<int>(tree_begin_.size());
  const int q = options_.tree_order, nm = (q + 1) * (q + 2) * (q + 3) / 6, padded = (nm + 7) / 8 * 8;
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

void StokesSingleLayer::mixed_sum(double xi, double yi, double zi, std::vector<MixedRange>& ranges, double* u) const {
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
             u);
}

}  // namespace bendlab
