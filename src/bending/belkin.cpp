#include "bendlab/bending/belkin.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

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
  resolve_method_options(info(), options);  // D takes no options: refuses any
  return std::make_unique<BelkinMethod>();
}

MethodInfo BelkinMethod::info() {
  MethodInfo m{"D", "Belkin: heat-kernel Laplace-Beltrami operator in eq. (10), eq. (13)",
                {}, {}, &BelkinMethod::create};
  m.capabilities.cost = std::string("O(N^2)");
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
