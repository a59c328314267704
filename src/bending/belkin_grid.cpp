// The grid form of BelkinLaplacian (belkin.hpp): the cell list of a shape, each vertex's runs of
// points within its cut-off radius, the kept kernel weights, and the applies that scan those runs.
// The buffers are members of the operator and reused by prepare() for the next shape; the weight
// buffer also passes to the next operator built on the thread when one is destroyed (SpareWeights).
#include <algorithm>
#include <cmath>
#include <utility>

#include <omp.h>

#include "bendlab/bending/belkin.hpp"
#include "bendlab/bending/belkin_kernel.hpp"

namespace bendlab {

using namespace belkin_kernel;

namespace {
// The grid form's cells are this many times shorter along x (the rows) than across (build_grid).
constexpr double kRowCellDivisor = 2.0;

// The largest weight buffer a BelkinLaplacian of this thread released (~BelkinLaplacian): a
// shape's weights reuse its pages, which on some virtual machines cost more to touch afresh
// (tens of microseconds per 4 KiB page) than the sums that fill them.
struct SpareWeights {
  std::unique_ptr<double[]> data;
  std::size_t capacity = 0;
};
thread_local SpareWeights spare_weights;
}  // namespace

BelkinLaplacian::~BelkinLaplacian() {
  if (weights_.data && weights_.capacity >= spare_weights.capacity) {
    spare_weights.data = std::move(weights_.data);
    spare_weights.capacity = weights_.capacity;
  }
}

void BelkinLaplacian::cache_weights() {
  const GridKernels& kernels = grid_kernels();
  const int lanes = kernels.lanes;
  std::vector<std::size_t>& start = weight_start_;
  start.assign(static_cast<std::size_t>(n_) + 1, 0);
  for (int i = 0; i < n_; ++i) {
    std::size_t count = 0;
    for (int r = run_start_[i]; r < run_start_[i + 1]; r += 2)
      count += static_cast<std::size_t>((runs_[r + 1] - runs_[r] + lanes - 1) / lanes * lanes);
    start[i + 1] = start[i] + count;
  }
  if (start[n_] > options_.weight_cache_bytes / sizeof(double)) return;
  // Not zeroed: the pass below writes every entry before any apply reads it. The buffer of the
  // previous shape when it is large enough, else this thread's spare, else a new one.
  const std::size_t need = std::max<std::size_t>(weight_start_[n_], 1);
  if (weights_.capacity < need) {
    if (spare_weights.capacity >= need) {
      weights_.data = std::move(spare_weights.data);
      weights_.capacity = std::exchange(spare_weights.capacity, 0);
    } else {
      weights_.data.reset(new double[need]);
      weights_.capacity = need;
    }
  }
  has_weights_ = true;
  GridInput in = grid_input(point_array(0), point_array(1), point_array(2), point_array(3), point_array(4), nullptr,
                            max_exponent_);
  lap_positions_.resize(n_, 3);
#pragma omp parallel for schedule(dynamic, 64) firstprivate(in)
  for (int i = 0; i < n_; ++i) {
    set_vertex(in, qx_[i], qy_[i], qz_[i], qnorm_[i], kernel_area_[i], 0.0);
    double acc[3] = {0, 0, 0};
    kernels.weights[plane_test_[i] ? 1 : 0](in, runs_.data() + run_start_[i], (run_start_[i + 1] - run_start_[i]) / 2,
                                            weights_.data.get() + weight_start_[i], acc);
    const double a = kernel_area_[i];
    const double scale = 1.0 / (4.0 * M_PI * a * a);  // eq. (13) prefactor
    for (int col = 0; col < 3; ++col) lap_positions_(i, col) = scale * acc[col];
  }
}

void BelkinLaplacian::build_grid() {
  if (n_ == 0) {
    run_start_.assign(1, 0);
    return;
  }
  // Cells of 0.35 times the median cut-off radius across the rows (y, z) and half that along them
  // (x): a vertex scans the rows of cells that meet its ball; smaller cells read fewer points
  // outside the ball (measured at 81920 triangles with cubic cells: 680 points per vertex at 0.35,
  // 800 at 0.5, about 440 inside the ball) but make more, shorter runs, and more rows to list.
  // Shorter cells along x only trim the ends of the runs, at no cost in rows (measured: the two
  // applies 4 to 15 % faster than with cubic cells; 0.35 across measured best among 0.3 to 0.6).
  GridBuffers& gb = grid_buffers_;
  std::vector<double>& r = gb.radius;
  r.resize(n_);
  for (int i = 0; i < n_; ++i) r[i] = std::sqrt(4.0 * kernel_area_[i] * max_exponent_);
  std::vector<double>& sorted = gb.sorted;
  sorted.assign(r.begin(), r.end());
  std::nth_element(sorted.begin(), sorted.begin() + n_ / 2, sorted.end());
  double cell = 0.35 * sorted[n_ / 2];
  double hi[3];
  for (int d = 0; d < 3; ++d) {
    const std::vector<double>& q = d == 0 ? qx_ : d == 1 ? qy_ : qz_;
    lo_[d] = *std::min_element(q.begin(), q.end());
    hi[d] = *std::max_element(q.begin(), q.end());
  }
  // At most about 4 cells per vertex (and 1024 per axis), whatever the spread of a_i.
  const double max_cells = 4.0 * n_ + 64;
  for (;;) {
    const double side[3] = {cell / kRowCellDivisor, cell, cell};
    double count = 1;
    for (int d = 0; d < 3; ++d) count *= std::floor((hi[d] - lo_[d]) / side[d]) + 1;
    bool ok = count <= max_cells && cell > 0;
    for (int d = 0; d < 3; ++d) ok = ok && (hi[d] - lo_[d]) / side[d] < 1023;
    if (ok) break;
    cell = cell > 0 ? 1.25 * cell : 1.0;
  }
  cell_[0] = cell / kRowCellDivisor, cell_[1] = cell, cell_[2] = cell;
  for (int d = 0; d < 3; ++d) dims_[d] = static_cast<int>(std::floor((hi[d] - lo_[d]) / cell_[d])) + 1;
  auto coord = [&](double v, int d) { return std::clamp(static_cast<int>(std::floor((v - lo_[d]) / cell_[d])), 0, dims_[d] - 1); };
  const int ncells = dims_[0] * dims_[1] * dims_[2];
  std::vector<int>& cell_of = gb.cell_of;
  std::vector<int>& cell_start = gb.cell_start;
  cell_of.resize(n_);
  cell_start.assign(ncells + 1, 0);
  for (int p = 0; p < n_; ++p) {
    cell_of[p] = (coord(qz_[p], 2) * dims_[1] + coord(qy_[p], 1)) * dims_[0] + coord(qx_[p], 0);
    ++cell_start[cell_of[p] + 1];
  }
  for (int c = 0; c < ncells; ++c) cell_start[c + 1] += cell_start[c];
  order_.resize(n_);
  std::vector<int>& fill = gb.fill;
  fill.assign(cell_start.begin(), cell_start.end() - 1);
  for (int p = 0; p < n_; ++p) order_[fill[cell_of[p]]++] = p;  // stable: ascending p in a cell
  // The half-space test is needed only where the ball crosses the plane: for |p - x_i| <= r_i,
  // (p - c).(x_i - c) >= |x_i - c| (|x_i - c| - r_i) and |p - c| <= |x_i - c| + r_i, so every
  // point of the ball passes the test of the kernel when |x_i - c| - r_i > 1e-9 (|x_i - c| + r_i);
  // checked with 1e-6 and r_i enlarged by 1e-3 (the kernel's y <= ymax rounds), far beyond rounding.
  plane_test_.assign(n_, 0);
  for (int i = 0; i < n_; ++i) {
    const double ri = 1.001 * r[i];
    plane_test_[i] = options_.half_space && !(qnorm_[i] - ri > 1e-6 * (qnorm_[i] + ri));
  }
  // The neighbour lists, once per shape: for each vertex, the runs of sorted points (one per row
  // of cells) that meet its ball of radius r_i; every apply() scans only these. A run may hold
  // points outside the ball (the kernel tests every distance), never miss one inside, so cell
  // indices may be rounded outwards: truncation instead of floor, clamped to the grid. Each
  // thread lists a contiguous range of vertices; the lists are joined in vertex order.
  const int nx = dims_[0], ny = dims_[1], nz = dims_[2];
  const double inv_cell[3] = {1.0 / cell_[0], 1.0 / cell_[1], 1.0 / cell_[2]};
  auto cell_index = [&](double v, int d) { return static_cast<int>((v - lo_[d]) * inv_cell[d]); };
  run_start_.assign(n_ + 1, 0);
  std::vector<std::vector<int>>& parts = gb.parts;
  parts.resize(omp_get_max_threads());
  for (std::vector<int>& part : parts) part.clear();
#pragma omp parallel
  {
    const int threads = omp_get_num_threads(), t = omp_get_thread_num();
    const int i_begin = static_cast<int>(static_cast<long>(n_) * t / threads);
    const int i_end = static_cast<int>(static_cast<long>(n_) * (t + 1) / threads);
    std::vector<int>& runs = parts[t];
    runs.reserve(static_cast<std::size_t>(i_end - i_begin) * 48);
    for (int i = i_begin; i < i_end; ++i) {
      const double xi = qx_[i], yi = qy_[i], zi = qz_[i];
      const double r2 = r[i] * r[i], ri = r[i];
      // Distance from v to the interval of cell c along axis d.
      auto gap = [&](double v, int d, int c) {
        const double l = lo_[d] + c * cell_[d], h = l + cell_[d];
        return v < l ? l - v : (v > h ? v - h : 0.0);
      };
      const std::size_t first = runs.size();
      const int z0 = std::max(0, cell_index(zi - ri, 2)), z1 = std::min(nz - 1, cell_index(zi + ri, 2));
      const int y0 = std::max(0, cell_index(yi - ri, 1)), y1 = std::min(ny - 1, cell_index(yi + ri, 1));
      for (int cz = z0; cz <= z1; ++cz) {
        const double gz = gap(zi, 2, cz);
        for (int cy = y0; cy <= y1; ++cy) {
          const double gy = gap(yi, 1, cy);
          const double rest = r2 - gz * gz - gy * gy;
          if (rest < 0) continue;
          // The cells of this row within the ball: one contiguous run of points.
          const double rx = std::sqrt(rest);
          const int x0 = std::max(0, cell_index(xi - rx, 0)), x1 = std::min(nx - 1, cell_index(xi + rx, 0));
          if (x0 > x1) continue;
          const int base = (cz * ny + cy) * nx;
          const int k0 = cell_start[base + x0], k1 = cell_start[base + x1 + 1];
          if (k0 == k1) continue;
          if (runs.size() > first && runs.back() == k0) {
            runs.back() = k1;  // continues the previous run
          } else {
            runs.push_back(k0);
            runs.push_back(k1);
          }
        }
      }
      run_start_[i + 1] = static_cast<int>(runs.size() - first);
    }
  }
  // Joined: vertex i's runs at [run_start_[i], run_start_[i + 1]).
  for (int i = 0; i < n_; ++i) run_start_[i + 1] += run_start_[i];
  // Copied (a few MB, a fraction of a percent of the applies), not moved: both buffers stay for
  // the next shape.
  runs_.clear();
  runs_.reserve(run_start_[n_]);
  for (const std::vector<int>& part : parts) runs_.insert(runs_.end(), part.begin(), part.end());
  run_shared_ = false;
}

// The grid form (grid_sum_body): w a scalar field (out[0]), or null for Lap x (out[0..2]).
void BelkinLaplacian::apply_grid(const double* w, double* const* out, std::vector<double>& buffer) const {
  // The field in the points' (scan) order, 64-byte aligned, padded by zeros.
  buffer.assign(w ? n_ + kLanes + 8 : 0, 0.0);
  double* ws = w ? aligned64(buffer.data()) : nullptr;
  for (int k = 0; w && k < n_; ++k) ws[k] = w[order_[k]];
  GridInput in = grid_input(point_array(0), point_array(1), point_array(2), point_array(3), point_array(4), ws,
                            max_exponent_);
  const GridKernels& kernels = grid_kernels();
  const double* weights = has_weights_ ? weights_.data.get() : nullptr;
#pragma omp parallel for schedule(dynamic, 64) firstprivate(in)
  for (int i = 0; i < n_; ++i) {
    set_vertex(in, qx_[i], qy_[i], qz_[i], qnorm_[i], kernel_area_[i], w ? w[i] : 0.0);
    double acc[3] = {0, 0, 0};
    const int* runs = runs_.data() + run_start_[i];
    const int nruns = (run_start_[i + 1] - run_start_[i]) / 2;
    if (weights && w)  // (with weights, Lap x was summed when they were stored: apply_to_positions)
      kernels.cached(in, runs, nruns, weights + weight_start_[i], acc);
    else
      kernels.k[w ? 0 : 1][plane_test_[i] ? 1 : 0](in, runs, nruns, acc);
    const double a = kernel_area_[i];
    const double scale = 1.0 / (4.0 * M_PI * a * a);  // eq. (13) prefactor
    for (int col = 0; col < (w ? 1 : 3); ++col) out[col][i] = scale * acc[col];
  }
}

}  // namespace bendlab
