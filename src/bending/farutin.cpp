#include "bendlab/bending/farutin.hpp"

#include <fmt/format.h>

#include <omp.h>

#include <cmath>
#include <limits>

#include "bendlab/bending/variational_assembly.hpp"
#include "bendlab/mesh/neighbourhood.hpp"

namespace bendlab {

namespace {

using Vec5 = Eigen::Matrix<double, 5, 1>;
using Mat5 = Eigen::Matrix<double, 5, 5>;

/// The paraboloid has 5 unknowns (the node value is fixed), section 2.4.3.
constexpr int kMinNeighbours = 5;
/// Smallest admissible ratio min_k L_kk^2 / max_k M_kk of the Cholesky factor L of the 5 x 5
/// normal matrix M (columns scaled to unit size): below it the neighbours are taken not to
/// determine the paraboloid (the design matrix's condition number is then ~1e6 or worse). A cheap
/// stand-in for a condition number estimate.
constexpr double kMinPivotRatio = 1e-12;

/// Basis of the paraboloid without its constant term: (u, v, u^2/2, uv, v^2/2), eq. of section 2.4.3.
inline Vec5 basis(double xi, double eta) {
  Vec5 p;
  p << xi, eta, 0.5 * xi * xi, xi * eta, 0.5 * eta * eta;
  return p;
}

/// Scaled normal matrix M = sum_j phi_j phi_j^T and right-hand side r = sum_j phi_j h_j of the
/// height fit, phi_j = basis((u_j, v_j) / scale), h_j = (x_j - x0) . n0, in one pass: the sums
/// are taken in (u, v) and scaled afterwards (phi(u / s, v / s) = D phi(u, v), D = diag(1/s, 1/s,
/// 1/s^2, 1/s^2, 1/s^2)). Also sets the chart's scale: s^2 = mean(u^2 + v^2) = (M_00 + M_11) / m
/// before scaling.
void accumulate(FarutinFit& chart, const Vec3& x0, std::span<const Vec3> nb, Mat5& m, Vec5& r) {
  m.setZero();
  r.setZero();
  for (const Vec3& xj : nb) {
    const Vec3 d = xj - x0;
    const Vec5 p = basis(d.dot(chart.t1), d.dot(chart.t2));
    m.noalias() += p * p.transpose();
    r += p * d.dot(chart.n0);
  }
  chart.scale = std::sqrt((m(0, 0) + m(1, 1)) / static_cast<double>(nb.size()));
  const double inv_s = 1.0 / chart.scale;
  Vec5 dg;
  dg << inv_s, inv_s, inv_s * inv_s, inv_s * inv_s, inv_s * inv_s;
  m = dg.asDiagonal() * m * dg.asDiagonal();
  r = dg.asDiagonal() * r;
}

/// Cholesky factorisation of the 5 x 5 normal matrix, written out so that the compiler unrolls it
/// (Eigen's LLT calls out of line for the triangular solves, a large share of the fit's time).
class Cholesky5 {
 public:
  /// False when the matrix is (numerically) singular.
  bool compute(const Mat5& a) {
    for (int j = 0; j < 5; ++j) {
      double d = a(j, j);
      for (int k = 0; k < j; ++k) d -= l_(j, k) * l_(j, k);
      if (!(d > kMinPivotRatio * a.diagonal().maxCoeff())) return false;
      const double ljj = std::sqrt(d);
      l_(j, j) = ljj;
      inv_diag_[j] = 1.0 / ljj;
      for (int i = j + 1; i < 5; ++i) {
        double v = a(i, j);
        for (int k = 0; k < j; ++k) v -= l_(i, k) * l_(j, k);
        l_(i, j) = v * inv_diag_[j];
      }
    }
    return true;
  }
  Vec5 solve(const Vec5& b) const {
    Vec5 y;
    for (int i = 0; i < 5; ++i) {
      double v = b[i];
      for (int k = 0; k < i; ++k) v -= l_(i, k) * y[k];
      y[i] = v * inv_diag_[i];
    }
    for (int i = 4; i >= 0; --i) {
      double v = y[i];
      for (int k = i + 1; k < 5; ++k) v -= l_(k, i) * y[k];
      y[i] = v * inv_diag_[i];
    }
    return y;
  }

 private:
  Mat5 l_;
  Vec5 inv_diag_;
};

FarutinFit invalid_fit() {
  FarutinFit f;
  f.normal = Vec3::Constant(kNaN);
  f.H = f.K = kNaN;
  f.rings = 0;
  return f;
}

/// The neighbours of one node (mesh/neighbourhood.hpp) and their positions, in buffers reused
/// from node to node.
class Neighbourhood : public VertexRings {
 public:
  using VertexRings::VertexRings;
  /// Positions of the neighbours, in the order of vertices().
  std::span<const Vec3> gather(const Points& x) {
    const std::vector<int>& v = vertices();
    pts_.resize(v.size());
    for (std::size_t k = 0; k < v.size(); ++k) pts_[k] = x.row(v[k]).transpose();
    return pts_;
  }

 private:
  std::vector<Vec3> pts_;
};

}  // namespace

FarutinFit farutin_fit_point(const Vec3& x0, const Vec3& normal_guess, std::span<const Vec3> neighbours) {
  if (static_cast<int>(neighbours.size()) < kMinNeighbours) return invalid_fit();
  FarutinFit fit;
  fit.n0 = normal_guess.normalized();
  fit.t1 = fit.n0.unitOrthogonal();
  fit.t2 = fit.n0.cross(fit.t1);
  // Height h above the tangent plane of n0; the t1 and t2 components are fitted exactly (header).
  Mat5 m;
  Vec5 r;
  accumulate(fit, x0, neighbours, m, r);
  Cholesky5 llt;
  if (!(fit.scale > 0) || !llt.compute(m)) return invalid_fit();
  Vec5 c = llt.solve(r);  // coefficients in the scaled chart; back to (u, v):
  const double inv_s = 1.0 / fit.scale;
  c.head<2>() *= inv_s;
  c.tail<3>() *= inv_s * inv_s;
  const double a = c[0], b = c[1];
  fit.grad << a, b;
  fit.hess << c[2], c[3], c[3], c[4];

  // x_u = t1 + a n0, x_v = t2 + b n0: x_u x x_v = n0 - a t1 - b t2, |.| = W.
  const double w2 = 1 + a * a + b * b, w = std::sqrt(w2);
  fit.normal = (fit.n0 - a * fit.t1 - b * fit.t2) / w;
  // E = 1 + a^2, F = ab, G = 1 + b^2, EG - F^2 = W^2; L, M, N = h_uu / W, h_uv / W, h_vv / W.
  // The textbook (EN - 2FM + GL) / (2(EG - F^2)) is negative on a sphere with the outward normal
  // (the surface bends away from n); docs/conventions.md wants H = 1/R there, hence the minus sign.
  fit.H = -((1 + b * b) * c[2] - 2 * a * b * c[3] + (1 + a * a) * c[4]) / (2 * w2 * w);
  fit.K = (c[2] * c[4] - c[3] * c[3]) / (w2 * w2);

  // Lap w = g^ab (w_ab - Gamma^c_ab w_c) for the paraboloid w fitted like h, with
  // g = I + grad h grad h^T, g^-1 = I - grad h grad h^T / W^2 and
  // Gamma^c_ab w_c = g^cd (x_d . x_ab) w_c = h_ab (g^-1 grad h) . grad w = h_ab (grad h . grad w) / W^2:
  // Lap w = g^ab w_ab - T (grad h . grad w) / W^2, T = g^ab h_ab. It is linear in the scaled
  // coefficients c_w = M^-1 r (grad w = c_w[0..1] / s, w_ab = c_w[2..4] / s^2), Lap w = l . c_w,
  // so Lap w = (M^-1 l) . r with M symmetric.
  const Eigen::Matrix2d g_inv = Eigen::Matrix2d::Identity() - fit.grad * fit.grad.transpose() / w2;
  const double tr = g_inv.cwiseProduct(fit.hess).sum();
  Vec5 l;
  l << -tr * a * inv_s / w2, -tr * b * inv_s / w2, g_inv(0, 0) * inv_s * inv_s, 2 * g_inv(0, 1) * inv_s * inv_s,
      g_inv(1, 1) * inv_s * inv_s;
  fit.lap_weights = llt.solve(l);
  fit.rings = 1;
  return fit;
}

double farutin_laplacian_point(const FarutinFit& fit, const Vec3& x0, std::span<const Vec3> neighbours, double w0,
                               std::span<const double> w_neighbours) {
  if (!fit.valid()) return kNaN;
  Vec5 rhs = Vec5::Zero();
  const double inv_s = 1.0 / fit.scale;
  for (std::size_t j = 0; j < neighbours.size(); ++j) {
    const Vec3 d = neighbours[j] - x0;
    rhs += basis(d.dot(fit.t1) * inv_s, d.dot(fit.t2) * inv_s) * (w_neighbours[j] - w0);
  }
  return fit.lap_weights.dot(rhs);
}

// One thread's buffers: its neighbourhood (for one topology) and the values of a field on it.
struct FarutinWorkspace::Thread {
  explicit Thread(const Topology& t) : topology_id(t.id()), nb(t) {}
  std::uint64_t topology_id;  // Topology::id(): the address may be a later topology's
  Neighbourhood nb;
  std::vector<double> values;
};

FarutinWorkspace::FarutinWorkspace() = default;
FarutinWorkspace::~FarutinWorkspace() = default;

void FarutinWorkspace::prepare() {
  const auto n = static_cast<std::size_t>(omp_get_max_threads());
  if (threads_.size() < n) threads_.resize(n);
}

FarutinWorkspace::Thread& FarutinWorkspace::thread(int k, const Topology& topology) {
  std::unique_ptr<Thread>& slot = threads_[k];
  if (!slot || slot->topology_id != topology.id()) slot = std::make_unique<Thread>(topology);
  return *slot;
}

std::vector<FarutinFit> farutin_fit(const Topology& t, const Points& x, const Points& normal_guess, int rings) {
  FarutinWorkspace ws;
  std::vector<FarutinFit> fits;
  farutin_fit(t, x, normal_guess, rings, ws, fits);
  return fits;
}

void farutin_fit(const Topology& t, const Points& x, const Points& normal_guess, int rings, FarutinWorkspace& ws,
                 std::vector<FarutinFit>& fits) {
  const int n = t.num_vertices();
  fits.resize(n);
  ws.prepare();
#pragma omp parallel
  {
    Neighbourhood& nb = ws.thread(omp_get_thread_num(), t).nb;
#pragma omp for schedule(static)
    for (int i = 0; i < n; ++i) {
      nb.start(i);
      bool more = true;
      while (more && (nb.rings() < rings || static_cast<int>(nb.vertices().size()) < kMinNeighbours))
        more = nb.add_ring();
      const Vec3 x0 = x.row(i).transpose(), n0 = normal_guess.row(i).transpose();
      FarutinFit fit = farutin_fit_point(x0, n0, nb.gather(x));
      // A singular configuration (e.g. neighbours on a conic through the node): widen the support.
      while (!fit.valid() && nb.add_ring()) fit = farutin_fit_point(x0, n0, nb.gather(x));
      if (fit.valid()) fit.rings = nb.rings();
      fits[i] = fit;
    }
  }
}

void require_valid_fits(const std::vector<FarutinFit>& fits, std::string_view method) {
  for (std::size_t i = 0; i < fits.size(); ++i)
    if (!fits[i].valid())
      throw Error(fmt::format("method {}: no paraboloid fits the neighbourhood of vertex {}, even with every vertex "
                              "the mesh connects to it (the least-squares system is singular); the mesh is too "
                              "coarse or too symmetric for the fits: refine it",
                              method, i));
}

Scalars farutin_laplacian(const Topology& t, const Points& x, const std::vector<FarutinFit>& fits, const Scalars& w) {
  FarutinWorkspace ws;
  Scalars out;
  farutin_laplacian(t, x, fits, w, ws, out);
  return out;
}

void farutin_laplacian(const Topology& t, const Points& x, const std::vector<FarutinFit>& fits, const Scalars& w,
                       FarutinWorkspace& ws, Scalars& out) {
  const int n = t.num_vertices();
  out.resize(n);
  ws.prepare();
#pragma omp parallel
  {
    FarutinWorkspace::Thread& scratch = ws.thread(omp_get_thread_num(), t);
    Neighbourhood& nb = scratch.nb;
    std::vector<double>& values = scratch.values;
#pragma omp for schedule(static)
    for (int i = 0; i < n; ++i) {
      const FarutinFit& fit = fits[i];
      if (!fit.valid()) {
        out[i] = kNaN;
        continue;
      }
      nb.start(i);
      nb.grow_to(fit.rings);
      const auto& v = nb.vertices();
      values.resize(v.size());
      for (std::size_t k = 0; k < v.size(); ++k) values[k] = w[v[k]];
      out[i] = farutin_laplacian_point(fit, x.row(i).transpose(), nb.gather(x), w[i], values);
    }
  }
}

FarutinFields farutin_fields(const std::vector<FarutinFit>& fits) {
  FarutinFields out;
  farutin_fields(fits, out.normal, out.H, out.K);
  return out;
}

void farutin_fields(const std::vector<FarutinFit>& fits, Points& normal, Scalars& H, Scalars& K) {
  const auto n = static_cast<Eigen::Index>(fits.size());
  normal.resize(n, 3);
  H.resize(n);
  K.resize(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    normal.row(i) = fits[i].normal.transpose();
    H[i] = fits[i].H;
    K[i] = fits[i].K;
  }
}

OptionSpec farutin_rings_option() {
  return int_option("rings", 1, 3, 1,
                    "fitting support in rings of neighbours (widened where fewer than 5 or singular)");
}

int parse_farutin_rings(const MethodOptions& options, const std::string& method) {
  const MethodInfo schema{method, "", {farutin_rings_option()}, {}, nullptr};
  return static_cast<int>(option_int(resolve_method_options(schema, options), "rings"));
}

// Kept by the method instance and reused from call to call (method_workspace.hpp).
struct FarutinMethod::Workspace {
  MeshGeometry geometry;
  std::vector<FarutinFit> fits;
  FarutinWorkspace buffers;
};

FarutinMethod::FarutinMethod(int rings) : rings_(rings) {
  if (rings < 1) throw Error("method E: rings must be at least 1, got " + std::to_string(rings));
}

FarutinMethod::~FarutinMethod() = default;

std::unique_ptr<BendingMethod> FarutinMethod::create(const MethodOptions& options) {
  return std::make_unique<FarutinMethod>(parse_farutin_rings(options, "E"));
}

MethodInfo FarutinMethod::info() {
  MethodInfo m{"E", "Farutin: least-squares paraboloid fits for n, H, K and Lap H in eq. (10)",
                {farutin_rings_option()}, {}, &FarutinMethod::create};
  return m;
}

void FarutinMethod::fields(const Topology& topology, const Points& x, BendingResult& out) const {
  const auto ws = workspace_.acquire();
  MeshGeometry& geometry = ws->geometry;
  MeshGeometry::compute(topology, x, geometry);
  farutin_fit(topology, x, geometry.normal_mwa, rings_, ws->buffers, ws->fits);
  require_valid_fits(ws->fits, "E");
  farutin_fields(ws->fits, out.normal, out.H, out.K);
  farutin_laplacian(topology, x, ws->fits, out.H, ws->buffers, out.lapH);
  out.area.swap(geometry.mixed_area);  // no copy; next call the arrays are reused
}

}  // namespace bendlab
