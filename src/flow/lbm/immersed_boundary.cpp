#include "bendlab/flow/lbm/immersed_boundary.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include <omp.h>

namespace bendlab::lbm {

double ib_kernel(IbKernel kernel, double r) {
  const double a = std::abs(r);
  switch (kernel) {
    case IbKernel::Phi2:
      return a < 1.0 ? 1.0 - a : 0.0;
    case IbKernel::Phi3:
      if (a <= 0.5) return (1.0 + std::sqrt(1.0 - 3.0 * a * a)) / 3.0;
      if (a <= 1.5) return (5.0 - 3.0 * a - std::sqrt(std::max(0.0, 1.0 - 3.0 * (1.0 - a) * (1.0 - a)))) / 6.0;
      return 0.0;
    case IbKernel::Phi4:
      if (a <= 1.0) return (3.0 - 2.0 * a + std::sqrt(1.0 + 4.0 * a - 4.0 * a * a)) / 8.0;
      if (a <= 2.0) return (5.0 - 2.0 * a - std::sqrt(std::max(0.0, -7.0 + 12.0 * a - 4.0 * a * a))) / 8.0;
      return 0.0;
  }
  return 0.0;
}

double ib_kernel_half_width(IbKernel kernel) {
  switch (kernel) {
    case IbKernel::Phi2:
      return 1.0;
    case IbKernel::Phi3:
      return 1.5;
    case IbKernel::Phi4:
      return 2.0;
  }
  return 0.0;
}

namespace {
// i into [0, n): a stencil's index is at most a period outside, which a compare and an addition
// handle (the remainder, an integer division, cost more than the rest of the stencil).
int wrap(int i, int n) {
  if (i < 0) {
    i += n;
  } else if (i >= n) {
    i -= n;
  }
  return i >= 0 && i < n ? i : ((i % n) + n) % n;
}
}  // namespace

int ib_stencil_into(const std::array<int, 3>& n, bool walls, const Vec3& X, IbKernel kernel, std::size_t* node,
                    double* weight) {
  if (!X.allFinite()) throw Error("IB node position is not finite");
  const int m = static_cast<int>(std::ceil(ib_kernel_half_width(kernel)));
  int idx[3][4];
  double w[3][4];
  int count = 2 * m;
  for (int d = 0; d < 3; ++d) {
    const double g = X[d] + 0.5 * n[d] - 0.5;  // continuous node index
    const int base = static_cast<int>(std::floor(g)) - m + 1;
    for (int s = 0; s < count; ++s) {
      const int i = base + s;
      w[d][s] = ib_kernel(kernel, g - i);
      if (d == 2 && walls && (i < 0 || i >= n[2])) {
        if (w[d][s] != 0.0) {
          throw Error(fmt::format("IB node at z = {} is within the kernel's reach of a wall (walls at z = +-{})", X[2], 0.5 * n[2]));
        }
        idx[d][s] = 0;  // zero weight
      } else {
        idx[d][s] = wrap(i, n[d]);
      }
    }
  }
  int size = 0;
  for (int c = 0; c < count; ++c) {
    for (int b = 0; b < count; ++b) {
      const double wbc = w[1][b] * w[2][c];
      for (int a = 0; a < count; ++a) {
        node[size] = static_cast<std::size_t>(idx[0][a]) +
                           static_cast<std::size_t>(n[0]) * (static_cast<std::size_t>(idx[1][b]) +
                                                             static_cast<std::size_t>(n[1]) * static_cast<std::size_t>(idx[2][c]));
        weight[size] = w[0][a] * wbc;
        ++size;
      }
    }
  }
  return size;
}

IbStencil ib_stencil(const std::array<int, 3>& n, bool walls, const Vec3& X, IbKernel kernel) {
  IbStencil st;
  st.size = ib_stencil_into(n, walls, X, kernel, st.node.data(), st.weight.data());
  return st;
}

IbStencil ib_stencil(const Lattice& lattice, const Vec3& X, IbKernel kernel) {
  return ib_stencil({lattice.nx(), lattice.ny(), lattice.nz()}, lattice.config().walls, X, kernel);
}

void spread_forces(Lattice& lattice, const Points& X, const Points& F, IbKernel kernel) {
  if (X.rows() != F.rows()) throw Error(fmt::format("IB spreading: {} positions but {} forces", X.rows(), F.rows()));
  for (Eigen::Index k = 0; k < X.rows(); ++k) {
    const IbStencil st = ib_stencil(lattice, row(X, k), kernel);
    const Vec3 Fk = row(F, k);
    for (int s = 0; s < st.size; ++s) {
      if (st.weight[s] != 0.0) lattice.add_force(st.node[s], st.weight[s] * Fk);
    }
  }
}

void interpolate_velocity(const Lattice& lattice, const Points& X, Points& U, IbKernel kernel) {
  U.resize(X.rows(), 3);
  const Eigen::Index n = X.rows();
  bool failed = false;
  std::string message;
#pragma omp parallel for schedule(static) if (n >= 256)
  for (Eigen::Index k = 0; k < n; ++k) {
    try {
      const IbStencil st = ib_stencil(lattice, row(X, k), kernel);
      Vec3 u = Vec3::Zero();
      for (int s = 0; s < st.size; ++s) {
        if (st.weight[s] != 0.0) u += st.weight[s] * lattice.velocity(st.node[s]);
      }
      U.row(k) = u.transpose();
    } catch (const Error& e) {
#pragma omp critical
      {
        failed = true;
        message = e.what();
      }
    }
  }
  if (failed) throw Error(message);
}

void IbInterpolator::prepare(const Lattice& lattice, const Points& X, IbKernel kernel) {
  const int m = static_cast<int>(std::ceil(ib_kernel_half_width(kernel)));
  per_node_ = 8 * m * m * m;  // (2 m)^3
  nodes_ = X.rows();
  lattice_nodes_ = lattice.num_nodes();
  node_.resize(static_cast<std::size_t>(nodes_) * per_node_);
  weight_.resize(node_.size());
  const std::array<int, 3> n = {lattice.nx(), lattice.ny(), lattice.nz()};
  const bool walls = lattice.config().walls;
  bool failed = false;
  std::string message;
#pragma omp parallel for schedule(static) if (nodes_ >= 256)
  for (Eigen::Index k = 0; k < nodes_; ++k) {
    try {
      const std::size_t at = static_cast<std::size_t>(k) * per_node_;
      ib_stencil_into(n, walls, row(X, k), kernel, node_.data() + at, weight_.data() + at);
    } catch (const Error& e) {
#pragma omp critical
      {
        if (!failed) message = fmt::format("IB node {}: {}", k, e.what());
        failed = true;
      }
    }
  }
  if (failed) {
    nodes_ = 0;
    throw Error(message);
  }
  plan_runs(lattice);
}

void IbInterpolator::spread(Lattice& lattice, const Points& F) const {
  if (F.rows() != nodes_) throw Error(fmt::format("IB spreading: {} prepared positions but {} forces", nodes_, F.rows()));
  if (lattice.num_nodes() != lattice_nodes_) throw Error("IB spreading: the stencils were prepared on another lattice");
  // Many stencils on several threads: each thread owns a range of lattice nodes and adds, from every
  // stencil in vertex order, the entries that fall in its range. Each node then sums its entries in
  // the serial order below, bit for bit, whatever the thread count.
  // The field is written directly; the lattice's next clear_force clears the touched runs only.
  double* f = lattice.force_field_for_writing(runs_);
  const std::size_t stride = lattice.slot_stride();
  const std::size_t entries = static_cast<std::size_t>(nodes_) * static_cast<std::size_t>(per_node_);
  if (omp_get_max_threads() > 1 && entries >= lattice_nodes_ / 8) {
#pragma omp parallel
    {
      const auto t = static_cast<std::size_t>(omp_get_thread_num()), T = static_cast<std::size_t>(omp_get_num_threads());
      const std::size_t lo = lattice_nodes_ * t / T, hi = lattice_nodes_ * (t + 1) / T;
      for (Eigen::Index k = 0; k < nodes_; ++k) {
        const std::size_t at = static_cast<std::size_t>(k) * per_node_;
        for (int s = 0; s < per_node_; ++s) {
          const std::size_t node = node_[at + s];
          const double w = weight_[at + s];
          if (w == 0.0 || node < lo || node >= hi) continue;
          const Vec3 wF = w * row(F, k);
          f[node] += wF.x();
          f[stride + node] += wF.y();
          f[2 * stride + node] += wF.z();
        }
      }
    }
    return;
  }
  for (Eigen::Index k = 0; k < nodes_; ++k) {
    const Vec3 Fk = row(F, k);
    const std::size_t at = static_cast<std::size_t>(k) * per_node_;
    for (int s = 0; s < per_node_; ++s) {
      const double w = weight_[at + s];
      if (w == 0.0) continue;
      const std::size_t node = node_[at + s];
      const Vec3 wF = w * Fk;  // Lattice::add_force's arithmetic
      f[node] += wF.x();
      f[stride + node] += wF.y();
      f[2 * stride + node] += wF.z();
    }
  }
}

void IbInterpolator::plan_runs(const Lattice& lattice) {
  const std::size_t n = lattice.num_nodes();
  // The nodes in some stencil, ascending.
  marks_.assign((n + 63) / 64, 0);
  for (std::size_t e = 0; e < node_.size(); ++e)
    if (weight_[e] != 0.0) marks_[node_[e] / 64] |= std::uint64_t{1} << (node_[e] % 64);
  touched_.clear();
  for (std::size_t w = 0; w < marks_.size(); ++w)
    for (std::uint64_t bits = marks_[w]; bits != 0; bits &= bits - 1)
      touched_.push_back(64 * w + static_cast<std::size_t>(__builtin_ctzll(bits)));
  if (velocity_.size() != 3 * n) velocity_.assign(3 * n, 0.0);
  const std::size_t nx = static_cast<std::size_t>(lattice.nx());
  runs_.clear();
  for (std::size_t t = 0; t < touched_.size();) {
    const std::size_t first = touched_[t], row_end = (first / nx + 1) * nx;
    std::size_t end = t + 1;
    while (end < touched_.size() && touched_[end] == touched_[end - 1] + 1 && touched_[end] < row_end) ++end;
    runs_.push_back({first, static_cast<int>(end - t)});
    t = end;
  }
}

void IbInterpolator::gather_runs(const Lattice& lattice) {
  // Their velocities, a run of consecutive touched nodes of one x-row at a time
  // (Lattice::velocities_of_run: velocity() bit for bit, the run's slots read together).
  const auto runs = static_cast<std::ptrdiff_t>(runs_.size());
  const bool all = gathered_.empty();
#pragma omp parallel for schedule(static) if (touched_.size() >= 4096)
  for (std::ptrdiff_t r = 0; r < runs; ++r) {
    if (!all && gathered_[static_cast<std::size_t>(r)]) continue;
    const Lattice::NodeRun& run = runs_[static_cast<std::size_t>(r)];
    lattice.velocities_of_run(run.first, run.count, velocity_.data() + 3 * run.first);
  }
}

void IbInterpolator::sum_stencils(Points& U) const {
  U.resize(nodes_, 3);
#pragma omp parallel for schedule(static) if (nodes_ >= 1024)
  for (Eigen::Index k = 0; k < nodes_; ++k) {
    const std::size_t at = static_cast<std::size_t>(k) * per_node_;
    Vec3 u = Vec3::Zero();
    for (int s = 0; s < per_node_; ++s) {
      const double w = weight_[at + s];
      if (w == 0.0) continue;
      const double* v = velocity_.data() + 3 * node_[at + s];
      u += w * Vec3(v[0], v[1], v[2]);
    }
    U.row(k) = u.transpose();
  }
}

void IbInterpolator::interpolate(const Lattice& lattice, Points& U) {
  if (lattice.num_nodes() != lattice_nodes_) throw Error("IB interpolation: the stencils were prepared on another lattice");
  gathered_.clear();
  gather_runs(lattice);
  sum_stencils(U);
}

void IbInterpolator::step_and_interpolate(Lattice& lattice, Points& U) {
  if (lattice.num_nodes() != lattice_nodes_) throw Error("IB interpolation: the stencils were prepared on another lattice");
  lattice.step_gathering(runs_, velocity_.data(), gathered_);
  gather_runs(lattice);
  sum_stencils(U);
}

void IbInterpolator::interpolate(const Lattice& lattice, const Points& X, Points& U, IbKernel kernel) {
  prepare(lattice, X, kernel);
  interpolate(lattice, U);
}

void euler_move(Points& X, const Points& U, double dt) {
  if (X.rows() != U.rows()) throw Error(fmt::format("IB move: {} positions but {} velocities", X.rows(), U.rows()));
  X += dt * U;
}

void ib_step(Lattice& lattice, Points& X, const Points& F, Points& U, IbKernel kernel) {
  lattice.clear_force();
  spread_forces(lattice, X, F, kernel);
  lattice.step();
  interpolate_velocity(lattice, X, U, kernel);
  euler_move(X, U, 1.0);
}

}  // namespace bendlab::lbm
