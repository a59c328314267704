#include "bendlab/bending/belkin.hpp"

#include <cmath>
#include <numeric>
#include <string>

#include "bendlab/bending/belkin_kernel.hpp"
#include "bendlab/geometry/measures.hpp"

namespace bendlab {

using namespace belkin_kernel;

BelkinLaplacian::BelkinLaplacian(const Topology& topology, const Points& x, const MeshGeometry& geometry,
                                 BelkinOptions options) {
  prepare(topology, x, geometry, options);
}

void BelkinLaplacian::prepare(const Topology& topology, const Points& x, const MeshGeometry& geometry,
                              BelkinOptions options) {
  options_ = options;
  n_ = topology.num_vertices();
  has_weights_ = false;
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
  // The point arrays, each padded by kLanes zeros (the kernels read whole blocks), an odd number
  // of cache lines apart (arrays a multiple of 4 KiB apart make the kernels' loads of one point
  // collide in the cache).
  stride_ = (static_cast<std::size_t>(n_) + kLanes + 7) / 8 * 8;
  if (stride_ / 8 % 2 == 0) stride_ += 8;
  points_.assign(5 * stride_ + 8, 0.0);
  if (options_.neighbours == BelkinOptions::Neighbours::grid) {
    if (!(options_.kernel_cutoff > 0) || !(options_.kernel_cutoff < 1))
      throw Error("belkin_laplacian: kernel_cutoff must be in (0, 1), got " + std::to_string(options_.kernel_cutoff));
    max_exponent_ = std::min(kMaxExponent, -std::log(options_.kernel_cutoff));
    build_grid();
  } else {
    // The reference: every vertex scans every point, in vertex order (one run).
    max_exponent_ = kMaxExponent;
    order_.resize(n_);
    for (int p = 0; p < n_; ++p) order_[p] = p;
    runs_.assign({0, n_});
    run_shared_ = true;
  }
  double* arrays = aligned64(points_.data());
  for (int k = 0; k < n_; ++k) {
    const int p = order_[k];
    arrays[k] = qx_[p];
    arrays[stride_ + k] = qy_[p];
    arrays[2 * stride_ + k] = qz_[p];
    arrays[3 * stride_ + k] = qnorm_[p];
    arrays[4 * stride_ + k] = lumped_area_[p];
  }
  if (!run_shared_) cache_weights();
}

const double* BelkinLaplacian::point_array(int j) const { return aligned64(points_.data()) + j * stride_; }

namespace {
void check_field_size(Eigen::Index size, int n, const char* what) {
  if (size != n)
    throw Error("belkin_laplacian: field has " + std::to_string(size) + " " + what + ", mesh has " + std::to_string(n) +
                " vertices");
}
}  // namespace

Scalars BelkinLaplacian::apply(const Scalars& w) const {
  check_field_size(w.size(), n_, "values");
  Scalars out(n_);
  std::vector<double> buffer;
  const double* in[1] = {w.data()};
  double* res[1] = {out.data()};
  if (run_shared_)
    apply_columns<1>(in, res, buffer);
  else
    apply_grid(w.data(), res, buffer);
  return out;
}

void BelkinLaplacian::apply_into(const Scalars& w, Scalars& out) {
  check_field_size(w.size(), n_, "values");
  out.resize(n_);
  const double* in[1] = {w.data()};
  double* res[1] = {out.data()};
  if (run_shared_)
    apply_columns<1>(in, res, field_buffer_);
  else
    apply_grid(w.data(), res, field_buffer_);
}

Points BelkinLaplacian::apply(const Points& w) const {
  check_field_size(w.rows(), n_, "rows");
  // Column-major copies so that the inner loop over p reads contiguous memory.
  const Eigen::MatrixXd wc = w;
  Eigen::MatrixXd oc(n_, 3);
  std::vector<double> buffer;
  const double* in[3] = {wc.col(0).data(), wc.col(1).data(), wc.col(2).data()};
  double* res[3] = {oc.col(0).data(), oc.col(1).data(), oc.col(2).data()};
  if (run_shared_) {
    apply_columns<3>(in, res, buffer);
  } else {
    for (int col = 0; col < 3; ++col) apply_grid(in[col], res + col, buffer);
  }
  return oc;
}

void BelkinLaplacian::apply_into(const Points& w, Points& out) {
  check_field_size(w.rows(), n_, "rows");
  columns_in_ = w;
  columns_out_.resize(n_, 3);
  const double* in[3] = {columns_in_.col(0).data(), columns_in_.col(1).data(), columns_in_.col(2).data()};
  double* res[3] = {columns_out_.col(0).data(), columns_out_.col(1).data(), columns_out_.col(2).data()};
  if (run_shared_) {
    apply_columns<3>(in, res, field_buffer_);
  } else {
    for (int col = 0; col < 3; ++col) apply_grid(in[col], res + col, field_buffer_);
  }
  out = columns_out_;
}

Points BelkinLaplacian::apply_to_positions() const {
  if (run_shared_) {
    Points q(n_, 3);
    for (int p = 0; p < n_; ++p) q.row(p) = Eigen::RowVector3d(qx_[p], qy_[p], qz_[p]);
    return apply(q);
  }
  if (has_weights_) return lap_positions_;  // computed with the weights
  Eigen::MatrixXd oc(n_, 3);
  std::vector<double> buffer;
  double* res[3] = {oc.col(0).data(), oc.col(1).data(), oc.col(2).data()};
  apply_grid(nullptr, res, buffer);
  return oc;
}

void BelkinLaplacian::apply_to_positions_into(Points& out) {
  if (run_shared_) {
    positions_buffer_.resize(n_, 3);
    for (int p = 0; p < n_; ++p) positions_buffer_.row(p) = Eigen::RowVector3d(qx_[p], qy_[p], qz_[p]);
    apply_into(positions_buffer_, out);
    return;
  }
  if (has_weights_) {
    out = lap_positions_;  // computed with the weights
    return;
  }
  columns_out_.resize(n_, 3);
  double* res[3] = {columns_out_.col(0).data(), columns_out_.col(1).data(), columns_out_.col(2).data()};
  apply_grid(nullptr, res, field_buffer_);
  out = columns_out_;
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

// Kept by the method instance and reused from call to call (method_workspace.hpp).
struct BelkinMethod::Workspace {
  MeshGeometry geometry;
  BelkinLaplacian laplacian;
  Points lap_x;
};

BelkinMethod::BelkinMethod(BelkinOptions options) : options_(options) {}
BelkinMethod::~BelkinMethod() = default;

void BelkinMethod::fields(const Topology& topology, const Points& x, BendingResult& out) const {
  const auto ws = workspace_.acquire();
  MeshGeometry& g = ws->geometry;
  MeshGeometry::compute(topology, x, g);
  BelkinLaplacian& lap = ws->laplacian;
  lap.prepare(topology, x, g, options_);
  // eq. (2) with eq. (13): Lap x = -2 H n.
  // The reference applies the operator to x itself (the grid form: to x - c, the same up to rounding).
  Points& lap_x = ws->lap_x;
  if (options_.neighbours == BelkinOptions::Neighbours::all)
    lap.apply_into(x, lap_x);
  else
    lap.apply_to_positions_into(lap_x);
  out.H.resize(topology.num_vertices());
  for (int i = 0; i < topology.num_vertices(); ++i) out.H[i] = -0.5 * lap_x.row(i).dot(g.normal_mwa.row(i));
  lap.apply_into(out.H, out.lapH);  // eq. (13) applied to H
  // The geometry's arrays change places with the result's (no copy; next call they are reused).
  out.normal.swap(g.normal_mwa);
  out.K.swap(g.gaussian_curvature);
  out.area.swap(g.mixed_area);
}

}  // namespace bendlab
