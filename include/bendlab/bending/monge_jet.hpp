#pragma once
// Method M (Monge jet; ../shared/spec/METHOD_M.md): at every node a least-squares height function
// of degree 6 (default; 4 and 5 as options) over the vertices within 3 edge-rings gives the normal, H
// and K of the fitted graph (graph_curvature.hpp); Lap_S H is the jets' Laplace-Beltrami operator
// applied to the field H (step 5); then the force density of eq. (10),
//   f = 2 kB (Lap H + 2 H (H^2 - K)) n,    F = f A_mixed (eq. (14)), as for C and E.
//
// Per vertex i:
// 1. Frame: n0 = the eigenvector of the smallest eigenvalue of sum_j (x_j - x_i)(x_j - x_i)^T over
//    the 2-ring of i, signed to agree with the angle-weighted (MWA) normal; option frame =
//    angle-weighted takes the MWA normal itself. t1, t2 complete a right-handed frame.
// 2. Support: the vertices within `rings` edge-rings (i excluded; option support_rings), widened ring
//    by ring while it has fewer than monge_jet_min_points(degree) points (31 for degree 6). The
//    support depends on the connectivity only, so the force is a smooth function of the positions.
//    Where it does not determine the jet (a singular fit: on a deformed cell, a patch that folds
//    over in the chart), the jet's degree is lowered on the same support, to 4 and then to 2
//    (MongeJetFit::degree), never the support widened: a wider support reaches farther round a
//    deformed cell and is worse (in a 10 um tube the widening once grew a support to all 641 other
//    vertices of the cell and still failed). Option support_points = k trims it to the k nearest to x_i (with
//    every point as near as the last one kept): where the mesh is graded (Rivara refinement) or a
//    vertex has valence 8-10, the 3-ring holds 50 and more points and reaches farther on the coarse
//    side, and k = 40 took r_max of f on the Rivara meshes of table 3 from 2.6 (MT2) and 2.4 (MT1) to
//    about 1.1-1.2 (docs/results/rbc.md). But the nearest-k rule makes the force jump as points
//    trade places, and its supports are ill-conditioned at places; on a moving cell that is fatal
//    (below), so the default keeps the rings whole (support_points = 0).
// 3. Fit: w = sum_{1 <= a+b <= degree} c_ab (u/s)^a (v/s)^b, s the RMS of |(u, v)| over the support;
//    unweighted least squares (option gaussian_weights: weights exp(-|(u,v)|^2 / (2 s^2))); no
//    constant term, the surface passes through x_i.
// 4. Height derivatives at the node: d^a_u d^b_v h = a! b! c_ab / s^(a+b), orders 1 to 4.
// 5. n, H, K of the graph (graph_curvature.hpp); n is turned into world coordinates. Lap_S H
//    (laplacian = field, the default) is the jet's Laplace-Beltrami operator at the node applied to
//    the field H of every node's jet (monge_jet_laplacian below), as E takes Lap H from a second fit
//    to its H, but with the degree-6 jet of the same chart and support: the discrete biharmonic is
//    one operator applied twice, as C's cotangent Laplacian is. Option laplacian = jet takes Lap_S H
//    from the jet's own third and fourth derivatives instead (graph_curvature.hpp), a stencil of
//    alternating signs.
//
// Why these defaults (field, untrimmed): with laplacian = jet and the 40-point trim (the defaults
// until M had to follow a moving cell) the force has modes that grow: the linearisation dF/dx has
// eigenvalues with real parts up to +200 on the unit sphere (1280 triangles), an equilibrium, and
// +524 on the RBC, and bendlab stretch did not hold a red cell still (docs/results/
// bending_stability.md). With the field operator on whole rings there are none beyond the small ones
// every method has on the RBC (C's included), and the static errors are smaller too: the maximum
// error of f on the RBC at 81920 triangles is 2.9e-5 (MT1), 1.2e-4 (MT2), 7.4e-4 (irregular) against
// 2.0e-4, 4.6e-4, 1.3e-3 (tests/bending/test_monge_jet.cpp). Its Jacobian is still far from
// symmetric (M is no energy's gradient), which an inertial relaxation cannot settle (see
// StretchRelaxation in flow/optical_stretch.hpp).
//
// Why degree 6 and not the spec's 5: a degree-5 jet's 4th derivatives carry an O(h^2) truncation
// error fed by the surface's 6th-order Taylor terms, which the symmetric supports of the regular
// families do not cancel. On the unit sphere at 5120 triangles it gives Lap H = +0.15 everywhere
// (C: 1e-6), a bias of 10 % of the force of a capsule in shear at G = 0.05, whose D_steady came out
// 3 % above C's, E's, J's and S's; at G = 0.2, kB_hat = 0.15 the degree-5 capsule became unstable
// at gamma t = 0.9 (5120 triangles) and 1.5 (1280), with RKC and with Cash-Karp alike. Degree 6 fits
// the 6th-order terms; the error left comes from the odd 7th-order terms, which such supports
// largely cancel: on the RBC its maximal error of f at 81920 triangles is 2e-4 (MT1), 1.3e-3
// (irregular), 2e-4 (octahedron, 131072) against degree 5's 8e-3 to 1e-2, it is also the more
// accurate from 5120 triangles on, and the capsule runs are stable (docs/results/shear.md).
#include <atomic>
#include <memory>
#include <mutex>
#include <span>
#include <string>
#include <unordered_map>
#include <vector>

#include "bendlab/bending/graph_curvature.hpp"
#include "bendlab/bending/method_registry.hpp"
#include "bendlab/bending/variational_assembly.hpp"
#include "bendlab/core/types.hpp"
#include "bendlab/mesh/topology.hpp"

namespace bendlab {

/// How the chart's normal n0 is chosen (step 1).
enum class MongeFrame { Covariance, AngleWeighted };

/// Where Lap_S H comes from (step 5): the jet's own third and fourth derivatives (Jet), or the
/// jet's Laplace-Beltrami operator at the node applied to the field H of every node's jet (Field;
/// monge_jet_laplacian below).
enum class MongeLaplacian { Jet, Field };

struct MongeJetSettings {
  int degree = 6;                          ///< 4, 5 or 6 (default 6: see the header comment)
  int rings = 3;                           ///< 2 or 3: the support before any widening
  MongeFrame frame = MongeFrame::Covariance;
  bool gaussian_weights = false;
  /// Step 2's trim: of the rings' points, the nearest this many and every point as near as the
  /// last of them are kept (0, the default: all). 40, a little more than a regular vertex's
  /// 3-ring (36), trims only the few widened supports of regular meshes and helps graded ones
  /// (see the header comment), but the nearest-40 rule makes the force jump as points trade places
  /// and leaves ill-conditioned supports whose modes grow in a moving cell.
  int support_points = 0;
  MongeLaplacian laplacian = MongeLaplacian::Field;
};

/// Unknowns of a jet of this degree without constant term: (degree + 1)(degree + 2)/2 - 1.
int monge_jet_unknowns(int degree);
/// Fewest support points a fit accepts: unknowns + 4 (24 for degree 5, as the spec's 3-ring rule).
int monge_jet_min_points(int degree);

/// The fit at one node.
struct MongeJetFit {
  bool valid = false;        ///< false: the support does not determine the jet (see reason)
  Vec3 t1 = Vec3::Zero(), t2 = Vec3::Zero(), n0 = Vec3::Zero();  ///< chart frame
  double scale = 0;          ///< s, the RMS tangential distance of the support
  HeightDerivatives derivatives;
  Vec3 normal = Vec3::Zero();  ///< unit, world coordinates, on the side of n0
  double H = 0, K = 0, lapH = 0;
  int rings = 0;             ///< rings of the support used (set by monge_jet_fit)
  int degree = 0;            ///< the fitted jet's degree (0 when invalid): in monge_jet_fit the
                             ///< setting's, or 4 or 2 where that one was not determined by the support
  int points = 0;            ///< support points used
};

/// The covariance normal of step 1: smallest-eigenvalue eigenvector of sum (x_j - x0)(x_j - x0)^T,
/// signed so that its dot product with `orientation` is not negative.
Vec3 covariance_normal(const Vec3& x0, std::span<const Vec3> points, const Vec3& orientation);

/// How the normal matrix of the fit is summed: from the support's moments sum w xi^p eta^q (the fast
/// path, used by the method) or as the sum of outer products phi phi^T (the plain reference).
enum class Accumulation { Moments, OuterProducts };

/// Steps 3-5 at one node: the jet of `degree` (2 to 6; below 4 the fallback of step 2) fitted to
/// `support` (positions, the node excluded) in the chart of unit normal n0. Invalid (valid = false) when there are fewer points than unknowns,
/// or the normal matrix is numerically singular.
MongeJetFit monge_jet_fit_point(const Vec3& x0, const Vec3& n0, std::span<const Vec3> support, int degree,
                                bool gaussian_weights = false, Accumulation accumulation = Accumulation::Moments);

/// Step 2's fallback where the support does not determine the jet of settings.degree: the jet of
/// degree 4 (if below settings.degree) and then of degree 2 on the same support, the first that is
/// determined (MongeJetFit::degree says which; invalid if neither is). A support that does not
/// determine a degree-6 jet has points on a curve of low degree in the chart (on a deformed cell:
/// a patch folded over in the tangent plane); a lower degree needs fewer independent directions.
MongeJetFit monge_jet_fallback_fit(const Vec3& x0, const Vec3& n0, std::span<const Vec3> support,
                                   const MongeJetSettings& settings);

/// One node's problem for monge_jet_fit_nodes: the node, its chart normal and its support.
struct MongeJetNode {
  Vec3 x0 = Vec3::Zero(), n0 = Vec3::Zero();
  std::span<const Vec3> support;
};

/// Steps 3-5 at many nodes, kJetLanes (8) at a time, their normal equations summed, factored and
/// solved side by side in SIMD lanes (monge_jet_solve.hpp): the fits monge_jet_fit_point gives (to
/// round-off; it is the reference this is tested against), in the order of `nodes`. The fast path
/// of monge_jet_fit; moments accumulation.
std::vector<MongeJetFit> monge_jet_fit_nodes(std::span<const MongeJetNode> nodes, int degree,
                                             bool gaussian_weights = false);

/// Step 2's supports, which depend on the connectivity only (built once per mesh and kept by the method): for every vertex the vertices within `rings`
/// rings, widened while fewer than monge_jet_min_points, listed ring after ring (VertexRings order).
struct MongeJetSupports {
  std::vector<int> offsets;     ///< N + 1: vertex i's support is vertices[offsets[i] .. offsets[i + 1])
  std::vector<int> vertices;
  std::vector<int> two_ring;    ///< N: how many of vertex i's support form its 2-ring (the frame's)
  std::vector<int> rings_used;  ///< N: rings of the support
  Faces faces;                  ///< the connectivity they were built for
  int rings = 0, min_points = 0;
  static MongeJetSupports build(const Topology& topology, const MongeJetSettings& settings);
  /// Built for this connectivity (faces compared entry by entry) and these settings.
  bool matches(const Topology& topology, const MongeJetSettings& settings) const;
};

/// The fit at every node, with the support rule of step 2 (and its fallback to a lower degree).
/// Throws bendlab::Error naming the method and the first vertex that cannot be fitted (too few
/// vertices in the whole connected mesh, or a singular system even at degree 2).
std::vector<MongeJetFit> monge_jet_fit(const Topology& topology, const Points& x, const Points& mwa_normal,
                                       const MongeJetSettings& settings);
/// The same with the supports built beforehand (refused, bendlab::Error, when they do not match).
std::vector<MongeJetFit> monge_jet_fit(const Topology& topology, const Points& x, const Points& mwa_normal,
                                       const MongeJetSettings& settings, const MongeJetSupports& supports);

/// Buffers of monge_jet_fit (each thread's supports and neighbourhood, built for one topology),
/// kept by the method from call to call so that the fits allocate nothing once warm.
class MongeJetWorkspace {
 public:
  MongeJetWorkspace();
  ~MongeJetWorkspace();
  MongeJetWorkspace(const MongeJetWorkspace&) = delete;
  MongeJetWorkspace& operator=(const MongeJetWorkspace&) = delete;
  struct Thread;
  /// Thread k's buffers for `topology` (made on first use or when the topology changes); call
  /// prepare() before the parallel region.
  Thread& thread(int k, const Topology& topology);
  /// Room for omp_get_max_threads() threads.
  void prepare();

 private:
  std::vector<std::unique_ptr<Thread>> threads_;
};

/// Lap_S of a field at every node as a stencil: (Lap_S w)_i = sum_k weights[i][k] (w[ids[i][k]] - w[i])
/// (monge_jet_laplacian's operator, its weights computed with the fits).
struct MongeJetLaplacianStencil {
  std::vector<std::vector<int>> ids;
  std::vector<std::vector<double>> weights;
  /// out (resized) = Lap_S w; allocates nothing when out has the size already.
  void apply(const Scalars& w, Scalars& out) const;
};

/// The same fits into `fits` (resized), with the buffers of `ws`; with `stencil`, also the
/// Laplace-Beltrami stencil of every node's jet (what monge_jet_laplacian applies), from the fits'
/// own factorisations (solve_jet_lanes): Method M's laplacian = field for the cost of two more
/// triangular solves per node, not a second fit.
void monge_jet_fit(const Topology& topology, const Points& x, const Points& mwa_normal,
                   const MongeJetSettings& settings, const MongeJetSupports& supports, MongeJetWorkspace& ws,
                   std::vector<MongeJetFit>& fits, MongeJetLaplacianStencil* stencil = nullptr);

/// Lap_S w at every node for a field w given at the nodes (the reference of MongeJetLaplacianStencil,
/// computed again from the positions and the fits, one node at a time): at node i, the Laplace-Beltrami operator
/// of the graph of i's fitted jet (its metric from the jet's first and second derivatives) applied
/// to the jet of the same degree fitted by least squares, on the same chart and support, to
/// w_j - w_i: a linear combination sum_j l_ij (w_j - w_i) over the support (the weights l_ij do not
/// depend on w). `fits` are monge_jet_fit's for the same shape, settings and supports.
void monge_jet_laplacian(const Topology& topology, const Points& x, const MongeJetSettings& settings,
                         const MongeJetSupports& supports, const std::vector<MongeJetFit>& fits, const Scalars& w,
                         Scalars& out);

/// Method M.
class MongeJetMethod : public VariationalMethod {
 public:
  explicit MongeJetMethod(MongeJetSettings settings = {});
  ~MongeJetMethod() override;
  static std::unique_ptr<BendingMethod> create(const MethodOptions& options);
  /// The method's entry in the registry (method_registry.hpp): description, options, capabilities.
  static MethodInfo info();

  std::string name() const override { return "M"; }
  /// Vertex evaluations whose jet fell back to degree 4 or 2 (step 2), over every call so far.
  long fallback_count() const override { return fallbacks_.load(std::memory_order_relaxed); }

 protected:
  /// n, H, K, lapH from the jets and the mixed area; eq. (10) and c0 / ADE are VariationalMethod's.
  void fields(const Topology& topology, const Points& x, BendingResult& out) const override;

 public:
  const MongeJetSettings& settings() const { return settings_; }

 private:
  /// The supports of a connectivity, built on first use and kept (a flow run's meshes keep theirs).
  std::shared_ptr<const MongeJetSupports> supports_for(const Topology& topology) const;
  static constexpr std::size_t kMaxCachedTopologies = 4;
  MongeJetSettings settings_;
  mutable std::atomic<long> fallbacks_{0};
  mutable std::mutex cache_mutex_;
  mutable std::unordered_map<const Topology*, std::shared_ptr<const MongeJetSupports>> cache_;
  struct Workspace;
  /// The geometry, the fits and their buffers of the last call, kept between calls.
  MethodWorkspace<Workspace> workspace_;
};

}  // namespace bendlab
