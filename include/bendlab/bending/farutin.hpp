#pragma once
// Method E (Farutin et al.; paper section 2.4.3): least-squares paraboloids on a node's
// neighbourhood give the normal, H, K and, from a second paraboloid fitted to H, Lap H; then
// f = 2 kB (Lap H + 2 H (H^2 - K)) n, eq. (10), with the signs of docs/conventions.md.
//
// The fit at node i, in the local frame (t1, t2, n0) with n0 the MWA normal and
// (u, v) = ((x_j - x_i) . t1, (x_j - x_i) . t2):
//   x_l(u, v) ~ x_l(0) + a_l u + b_l v + c_l u^2/2 + d_l uv + e_l v^2/2,   l = 1, 2, 3,
// least squares over the neighbours, the node value exact. The three fits share one 5 x 5 normal
// matrix, and because the data of the t1 and t2 components are u and v themselves (two columns of
// the design matrix) their fits are exact: x_u = t1 + h_u n0, x_v = t2 + h_v n0, x_ab = h_ab n0,
// where h(u, v) is the fit of the n0 component (the height above the tangent plane). So the
// paper's three 5 x 5 systems reduce to one, with the same result (tested).
//
// Neighbourhood: rings 1..R of the breadth-first search (R = option "rings"), extended by further
// rings while it holds fewer than 5 vertices or while the 5 x 5 system is singular.
//
// Lap H: the paraboloid H(u, v) ~ H_i + p u + q v + r u^2/2 + s uv + w v^2/2 is fitted over the
// same neighbourhood in the same chart, with H_i fixed at the node's value (the same normal matrix
// as the coordinate fit), and Lap H = g^ab (H_ab - Gamma^c_ab H_c) with the metric and the
// Christoffel symbols Gamma^c_ab = g^cd x_d . x_ab of the coordinate fit at the node.
// With the height form: g = I + grad h grad h^T, Gamma^c_ab = h_ab h_c / W^2, W^2 = 1 + |grad h|^2.
#include <memory>
#include <span>
#include <string_view>
#include <vector>

#include "bendlab/bending/method_registry.hpp"
#include "bendlab/bending/variational_assembly.hpp"
#include "bendlab/core/types.hpp"
#include "bendlab/geometry/mesh_geometry.hpp"
#include "bendlab/mesh/topology.hpp"

namespace bendlab {

/// The coordinate fit of Method E at one node.
struct FarutinFit {
  Vec3 t1 = Vec3::Zero(), t2 = Vec3::Zero(), n0 = Vec3::Zero();  ///< chart frame, t1 x t2 = n0
  double scale = 0;               ///< RMS tangential distance of the neighbours (column scaling)
  Eigen::Vector2d grad = Eigen::Vector2d::Zero();  ///< (h_u, h_v)
  Eigen::Matrix2d hess = Eigen::Matrix2d::Zero();  ///< (h_uu, h_uv; h_uv, h_vv)
  Vec3 normal = Vec3::Zero();     ///< refined normal x_u x x_v / |.|, on the side of n0
  double H = 0, K = 0;            ///< mean (> 0 on a sphere) and Gaussian curvature
  /// Lap w = lap_weights . sum_j phi_j (w_j - w_i), phi_j the paraboloid basis at neighbour j in
  /// the scaled chart: the Laplace-Beltrami of the fitted paraboloid, folded with the inverse of the
  /// normal matrix, so that a field's Lap needs no second factorisation.
  Eigen::Matrix<double, 5, 1> lap_weights = Eigen::Matrix<double, 5, 1>::Zero();
  int rings = 0;                  ///< rings of the neighbourhood used (0: no fit possible)
  bool valid() const { return rings > 0; }
};

/// Fits the paraboloid at a node x0 from its neighbours' positions; normal_guess (unit) fixes the
/// chart and the side of the normal. Returns a fit with rings = 1 on success and rings = 0 (and
/// NaN H, K, normal) when the neighbours do not determine the paraboloid (fewer than 5, or a
/// singular configuration).
FarutinFit farutin_fit_point(const Vec3& x0, const Vec3& normal_guess, std::span<const Vec3> neighbours);

/// Lap w at the node of `fit` from the values w0 at the node and w_neighbours at `neighbours`
/// (the same neighbours as the fit, same order), by the quadratic fit described above.
double farutin_laplacian_point(const FarutinFit& fit, const Vec3& x0, std::span<const Vec3> neighbours,
                               double w0, std::span<const double> w_neighbours);

/// The fit at every node, normal_guess the MWA normals; rings >= 1 (see the neighbourhood rule).
std::vector<FarutinFit> farutin_fit(const Topology& topology, const Points& x, const Points& normal_guess,
                                    int rings);

/// Buffers of farutin_fit and farutin_laplacian (each thread's neighbourhood, built for one
/// topology), kept by a method from call to call so that the fits allocate nothing once warm.
class FarutinWorkspace {
 public:
  FarutinWorkspace();
  ~FarutinWorkspace();
  FarutinWorkspace(const FarutinWorkspace&) = delete;
  FarutinWorkspace& operator=(const FarutinWorkspace&) = delete;
  struct Thread;
  /// Thread k's buffers for `topology` (made on first use, or when the topology changes); call
  /// prepare() before the parallel region.
  Thread& thread(int k, const Topology& topology);
  /// Room for omp_get_max_threads() threads.
  void prepare();

 private:
  std::vector<std::unique_ptr<Thread>> threads_;
};

/// The same fits into `fits` (resized), with the buffers of `ws`.
void farutin_fit(const Topology& topology, const Points& x, const Points& normal_guess, int rings,
                 FarutinWorkspace& ws, std::vector<FarutinFit>& fits);

/// Throws bendlab::Error naming `method` and the first vertex whose fit is invalid: no support
/// the mesh offers determines its paraboloid (the bare octahedron, for instance, where every
/// neighbourhood is symmetric enough to leave the xy term free). Called before any further work.
void require_valid_fits(const std::vector<FarutinFit>& fits, std::string_view method);

/// Lap w at every node on the neighbourhoods and charts of `fits` (NaN where a fit is invalid).
Scalars farutin_laplacian(const Topology& topology, const Points& x, const std::vector<FarutinFit>& fits,
                          const Scalars& w);
/// The same into `out` (resized), with the buffers of `ws`.
void farutin_laplacian(const Topology& topology, const Points& x, const std::vector<FarutinFit>& fits,
                       const Scalars& w, FarutinWorkspace& ws, Scalars& out);

/// Normal, H and K of every node, in vertex order (NaN where a fit is invalid).
struct FarutinFields {
  Points normal;
  Scalars H, K;
};
FarutinFields farutin_fields(const std::vector<FarutinFit>& fits);
/// The same into the three arrays (resized).
void farutin_fields(const std::vector<FarutinFit>& fits, Points& normal, Scalars& H, Scalars& K);

/// The schema of the option "rings" (integer 1..3, default 1), shared by Methods E and ED.
OptionSpec farutin_rings_option();
/// Reads the option "rings" (1, 2 or 3; default 1); throws bendlab::Error for any other option or
/// value. Shared by Methods E and ED.
int parse_farutin_rings(const MethodOptions& options, const std::string& method);

/// Method E.
class FarutinMethod : public VariationalMethod {
 public:
  explicit FarutinMethod(int rings = 1);
  ~FarutinMethod() override;
  static std::unique_ptr<BendingMethod> create(const MethodOptions& options);
  /// The method's entry in the registry (method_registry.hpp): description, options, capabilities.
  static MethodInfo info();

  std::string name() const override { return "E"; }

 protected:
  /// n, H, K, lapH from the fits and the mixed area; eq. (10) and c0 / ADE are VariationalMethod's.
  void fields(const Topology& topology, const Points& x, BendingResult& out) const override;

 public:
  int rings() const { return rings_; }

 private:
  int rings_;
  struct Workspace;
  /// The geometry, the fits and their buffers of the last call, kept between calls.
  MethodWorkspace<Workspace> workspace_;
};

}  // namespace bendlab
