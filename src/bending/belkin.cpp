#include "bendlab/bending/belkin.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>

#include "bendlab/bending/variational_assembly.hpp"
#include "bendlab/geometry/measures.hpp"

namespace bendlab {

namespace {
// Terms with |p - x_i|^2 / (4 a_i) above this are skipped; see the bound in belkin.hpp.
constexpr double kMaxExponent = 80.0;
// Vertices p are scanned in blocks: a branch-free pass computes the exponents of a block
// (vectorised), a second pass evaluates exp only where the term survives.
constexpr int kBlock = 256;
// A point p counts as above the plane of x_i when (p - c).(x_i - c) > kPlaneTolerance |p - c| |x_i - c|.
// Symmetric meshes put nodes exactly on the plane (the rim of a red blood cell for a node at a
// dimple centre); without the margin, rounding in c would decide whether those nodes count, so
// the result would change under a rotation or a scaling of the shape. Such nodes are left out, as
// the strict inequality of the rule says for points on the plane.
constexpr double kPlaneTolerance = 1e-9;
}  // namespace

BelkinLaplacian::BelkinLaplacian(const Topology& topology, const Points& x, const MeshGeometry& geometry,
                                 BelkinOptions options)
    : options_(options), n_(topology.num_vertices()) {
  const Vec3 c = volume_centroid(topology, x);
  qx_.resize(n_);
  qy_.resize(n_);
  qz_.resize(n_);
  qnorm_.resize(n_);
  for (int p = 0; p < n_; ++p) {
    qx_[p] = x(p, 0) - c.x();
    qy_[p] = x(p, 1) - c.y();
    qz_[p] = x(p, 2) - c.z();
    qnorm_[p] = std::sqrt(qx_[p] * qx_[p] + qy_[p] * qy_[p] + qz_[p] * qz_[p]);
  }
  // sum_t A_t/3 sum_{p in V(t)} of eq. (13) regrouped by vertex.
  lumped_area_ = Scalars::Zero(n_);
  const Faces& F = topology.faces();
  for (int f = 0; f < topology.num_faces(); ++f)
    for (int k = 0; k < 3; ++k) lumped_area_[F(f, k)] += geometry.face_area[f] / 3.0;
  kernel_area_ = geometry.mixed_area;
  if (options_.neighbours == BelkinOptions::Neighbours::grid) {
    if (!(options_.kernel_cutoff > 0) || !(options_.kernel_cutoff < 1))
      throw Error("belkin_laplacian: kernel_cutoff must be in (0, 1), got " + std::to_string(options_.kernel_cutoff));
    max_exponent_ = std::min(kMaxExponent, -std::log(options_.kernel_cutoff));
    build_grid();
  }
}

void BelkinLaplacian::build_grid() {
  if (n_ == 0) return;
  // Cells of half the median cut-off radius: a vertex scans about (2 r_i / cell + 1)^3 cells, most
  // of them pruned by their distance, and the points it reads are mostly inside its ball.
  std::vector<double> r(n_);
  for (int i = 0; i < n_; ++i) r[i] = std::sqrt(4.0 * kernel_area_[i] * max_exponent_);
  std::vector<double> sorted = r;
  std::nth_element(sorted.begin(), sorted.begin() + n_ / 2, sorted.end());
  double cell = 0.5 * sorted[n_ / 2];
  double hi[3];
  for (int d = 0; d < 3; ++d) {
    const std::vector<double>& q = d == 0 ? qx_ : d == 1 ? qy_ : qz_;
    lo_[d] = *std::min_element(q.begin(), q.end());
    hi[d] = *std::max_element(q.begin(), q.end());
  }
  // At most about 4 cells per vertex (and 1024 per axis), whatever the spread of a_i.
  const double max_cells = 4.0 * n_ + 64;
  for (;;) {
    double count = 1;
    for (int d = 0; d < 3; ++d) count *= std::floor((hi[d] - lo_[d]) / cell) + 1;
    bool ok = count <= max_cells && cell > 0;
    for (int d = 0; d < 3; ++d) ok = ok && (hi[d] - lo_[d]) / cell < 1023;
    if (ok) break;
    cell = cell > 0 ? 1.25 * cell : 1.0;
  }
  cell_ = cell;
  for (int d = 0; d < 3; ++d) dims_[d] = static_cast<int>(std::floor((hi[d] - lo_[d]) / cell_)) + 1;
  auto coord = [&](double v, int d) { return std::clamp(static_cast<int>(std::floor((v - lo_[d]) / cell_)), 0, dims_[d] - 1); };
  const int ncells = dims_[0] * dims_[1] * dims_[2];
  cell_of_.resize(n_);
  cell_start_.assign(ncells + 1, 0);
  for (int p = 0; p < n_; ++p) {
    cell_of_[p] = (coord(qz_[p], 2) * dims_[1] + coord(qy_[p], 1)) * dims_[0] + coord(qx_[p], 0);
    ++cell_start_[cell_of_[p] + 1];
  }
  for (int c = 0; c < ncells; ++c) cell_start_[c + 1] += cell_start_[c];
  order_.resize(n_);
  std::vector<int> fill(cell_start_.begin(), cell_start_.end() - 1);
  for (int p = 0; p < n_; ++p) order_[fill[cell_of_[p]]++] = p;  // stable: ascending p in a cell
  sx_.resize(n_), sy_.resize(n_), sz_.resize(n_), snorm_.resize(n_), slump_.resize(n_);
  for (int k = 0; k < n_; ++k) {
    const int p = order_[k];
    sx_[k] = qx_[p], sy_[k] = qy_[p], sz_[k] = qz_[p], snorm_[k] = qnorm_[p], slump_[k] = lumped_area_[p];
  }
}

template <int Cols>
void BelkinLaplacian::apply_columns_grid(const double* const* w, double* const* out) const {
  // The fields in cell order, so that the points of a row of cells are contiguous.
  std::vector<double> ws(static_cast<std::size_t>(Cols) * n_);
  for (int col = 0; col < Cols; ++col)
    for (int k = 0; k < n_; ++k) ws[static_cast<std::size_t>(col) * n_ + k] = w[col][order_[k]];
  const bool half_space = options_.half_space;
  const double emax = max_exponent_;
  const int nx = dims_[0], ny = dims_[1], nz = dims_[2];
  const double* sx = sx_.data();
  const double* sy = sy_.data();
  const double* sz = sz_.data();
  const double* sn = snorm_.data();
  const double* sl = slump_.data();
  const double inf = std::numeric_limits<double>::infinity();
#pragma omp parallel
  {
    std::array<double, kBlock> expo;
#pragma omp for schedule(dynamic, 64)
    for (int i = 0; i < n_; ++i) {
      const double xi = qx_[i], yi = qy_[i], zi = qz_[i];
      const double margin = kPlaneTolerance * qnorm_[i];
      const double a = kernel_area_[i];
      const double inv4a = 1.0 / (4.0 * a);
      const double r2 = 4.0 * a * emax;  // exponent <= emax  <=>  |p - x_i|^2 <= r2
      const double r = std::sqrt(r2);
      std::array<double, Cols> wi, acc;
      for (int col = 0; col < Cols; ++col) {
        wi[col] = w[col][i];
        acc[col] = 0.0;
      }
      auto range = [&](double v, int d, int n, int& c0, int& c1) {
        c0 = std::max(0, static_cast<int>(std::floor((v - r - lo_[d]) / cell_)));
        c1 = std::min(n - 1, static_cast<int>(std::floor((v + r - lo_[d]) / cell_)));
      };
      // Distance from v to the interval of cell c along axis d.
      auto gap = [&](double v, int d, int c) {
        const double l = lo_[d] + c * cell_, h = l + cell_;
        return v < l ? l - v : (v > h ? v - h : 0.0);
      };
      int z0, z1, y0, y1;
      range(zi, 2, nz, z0, z1);
      range(yi, 1, ny, y0, y1);
      for (int cz = z0; cz <= z1; ++cz) {
        const double gz = gap(zi, 2, cz);
        for (int cy = y0; cy <= y1; ++cy) {
          const double gy = gap(yi, 1, cy);
          const double rest = r2 - gz * gz - gy * gy;
          if (rest < 0) continue;
          // The cells of this row within the ball: one contiguous run of points.
          const double rx = std::sqrt(rest);
          const int x0 = std::max(0, static_cast<int>(std::floor((xi - rx - lo_[0]) / cell_)));
          const int x1 = std::min(nx - 1, static_cast<int>(std::floor((xi + rx - lo_[0]) / cell_)));
          if (x0 > x1) continue;
          const int base = (cz * ny + cy) * nx;
          const int k1 = cell_start_[base + x1 + 1];
          // As the reference form: a branch-free pass for the exponents, exp only where kept.
          for (int b0 = cell_start_[base + x0]; b0 < k1; b0 += kBlock) {
            const int len = std::min(kBlock, k1 - b0);
  #pragma omp simd
            for (int k = 0; k < len; ++k) {
              const int p = b0 + k;
              const double dx = sx[p] - xi, dy = sy[p] - yi, dz = sz[p] - zi;
              const double e = (dx * dx + dy * dy + dz * dz) * inv4a;
              const bool above = sx[p] * xi + sy[p] * yi + sz[p] * zi > margin * sn[p];
              expo[k] = (above || !half_space) ? e : inf;
            }
            for (int k = 0; k < len; ++k) {
              if (!(expo[k] <= emax)) continue;
              const int p = b0 + k;
              const double weight = sl[p] * std::exp(-expo[k]);
              for (int col = 0; col < Cols; ++col) acc[col] += weight * (ws[static_cast<std::size_t>(col) * n_ + p] - wi[col]);
            }
          }
        }
      }
      const double scale = 1.0 / (4.0 * M_PI * a * a);  // eq. (13) prefactor
      for (int col = 0; col < Cols; ++col) out[col][i] = scale * acc[col];
    }
  }
}

template <int Cols>
void BelkinLaplacian::apply_columns(const double* const* w, double* const* out) const {
  const double* qx = qx_.data();
  const double* qy = qy_.data();
  const double* qz = qz_.data();
  const double* qn = qnorm_.data();
  const double* lump = lumped_area_.data();
  const bool half_space = options_.half_space;
  const double inf = std::numeric_limits<double>::infinity();
#pragma omp parallel
  {
    std::array<double, kBlock> expo;
#pragma omp for schedule(dynamic, 16)
    for (int i = 0; i < n_; ++i) {
      const double xi = qx[i], yi = qy[i], zi = qz[i];
      const double margin = kPlaneTolerance * qn[i];
      const double a = kernel_area_[i];
      const double inv4a = 1.0 / (4.0 * a);
      std::array<double, Cols> wi, acc;
      for (int col = 0; col < Cols; ++col) {
        wi[col] = w[col][i];
        acc[col] = 0.0;
      }
      for (int p0 = 0; p0 < n_; p0 += kBlock) {
        const int len = std::min(kBlock, n_ - p0);
        // (p - c).(x_i - c) > 0: p lies above the plane through c with normal x_i - c.
#pragma omp simd
        for (int k = 0; k < len; ++k) {
          const int p = p0 + k;
          const double dx = qx[p] - xi, dy = qy[p] - yi, dz = qz[p] - zi;
          const double e = (dx * dx + dy * dy + dz * dz) * inv4a;
          const bool above = qx[p] * xi + qy[p] * yi + qz[p] * zi > margin * qn[p];
          expo[k] = (above || !half_space) ? e : inf;
        }
        for (int k = 0; k < len; ++k) {
          if (!(expo[k] <= kMaxExponent)) continue;
          const int p = p0 + k;
          const double weight = lump[p] * std::exp(-expo[k]);
          for (int col = 0; col < Cols; ++col) acc[col] += weight * (w[col][p] - wi[col]);
        }
      }
      const double scale = 1.0 / (4.0 * M_PI * a * a);  // eq. (13) prefactor
      for (int col = 0; col < Cols; ++col) out[col][i] = scale * acc[col];
    }
  }
}

Scalars BelkinLaplacian::apply(const Scalars& w) const {
  if (w.size() != n_) throw Error("belkin_laplacian: field has " + std::to_string(w.size()) + " values, mesh has " +
                                  std::to_string(n_) + " vertices");
  Scalars out(n_);
  const double* in[1] = {w.data()};
  double* res[1] = {out.data()};
  if (options_.neighbours == BelkinOptions::Neighbours::grid)
    apply_columns_grid<1>(in, res);
  else
    apply_columns<1>(in, res);
  return out;
}

Points BelkinLaplacian::apply(const Points& w) const {
  if (w.rows() != n_) throw Error("belkin_laplacian: field has " + std::to_string(w.rows()) + " rows, mesh has " +
                                  std::to_string(n_) + " vertices");
  // Column-major copies so that the inner loop over p reads contiguous memory.
  const Eigen::MatrixXd wc = w;
  Eigen::MatrixXd oc(n_, 3);
  const double* in[3] = {wc.col(0).data(), wc.col(1).data(), wc.col(2).data()};
  double* res[3] = {oc.col(0).data(), oc.col(1).data(), oc.col(2).data()};
  if (options_.neighbours == BelkinOptions::Neighbours::grid)
    apply_columns_grid<3>(in, res);
  else
    apply_columns<3>(in, res);
  return oc;
}

Scalars belkin_laplacian(const Topology& topology, const Points& x, const MeshGeometry& geometry, const Scalars& w,
                         const BelkinOptions& options) {
  return BelkinLaplacian(topology, x, geometry, options).apply(w);
}
Points belkin_laplacian(const Topology& topology, const Points& x, const MeshGeometry& geometry, const Points& w,
                        const BelkinOptions& options) {
  return BelkinLaplacian(topology, x, geometry, options).apply(w);
}
Scalars belkin_laplacian(const Topology& topology, const Points& x, const MeshGeometry& geometry, const Scalars& w) {
  return belkin_laplacian(topology, x, geometry, w, BelkinOptions{});
}
Points belkin_laplacian(const Topology& topology, const Points& x, const MeshGeometry& geometry, const Points& w) {
  return belkin_laplacian(topology, x, geometry, w, BelkinOptions{});
}

std::unique_ptr<BendingMethod> BelkinMethod::create(const MethodOptions& options) {
  const MethodOptions r = resolve_method_options(info(), options);
  BelkinOptions o;
  o.neighbours = r.at("neighbours") == "all" ? BelkinOptions::Neighbours::all : BelkinOptions::Neighbours::grid;
  o.kernel_cutoff = option_real(r, "kernel_cutoff");
  return std::make_unique<BelkinMethod>(o);
}

MethodInfo BelkinMethod::info() {
  MethodInfo m{"D", "Belkin: heat-kernel Laplace-Beltrami operator in eq. (10), eq. (13)",
                {choice_option("neighbours", {"grid", "all"}, "grid",
                               "grid: the points within the kernel's cutoff radius, through a cell list; all: every pair"),
                 real_option("kernel_cutoff", 1e-300, 0.5, 1e-15,
                             "heat-kernel weights below this are dropped (neighbours=grid)")},
                {}, &BelkinMethod::create};
  m.capabilities.cost = std::string("O(N)");
  return m;
}

BendingResult BelkinMethod::compute(const Topology& topology, const Points& x, double kappa_b) const {
  const MeshGeometry g = MeshGeometry::compute(topology, x);
  const BelkinLaplacian lap(topology, x, g, options_);
  // eq. (2) with eq. (13): Lap x = -2 H n.
  const Points lap_x = lap.apply(x);
  Scalars H(topology.num_vertices());
  for (int i = 0; i < topology.num_vertices(); ++i) H[i] = -0.5 * lap_x.row(i).dot(g.normal_mwa.row(i));
  Scalars lapH = lap.apply(H);  // eq. (13) applied to H
  return assemble_variational_result(g.normal_mwa, std::move(H), g.gaussian_curvature, std::move(lapH),
                                     g.mixed_area, kappa_b);
}

}  // namespace bendlab
