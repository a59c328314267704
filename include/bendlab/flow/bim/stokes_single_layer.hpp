#pragma once
// Stokes single-layer potential on a closed surface of flat triangles: the integral of the
// boundary integral equation (22), with the sign of docs/conventions.md §1 (traction jump
// Delta f^h = -f):
//
//   u_j(x_i) = 1/(8 pi mu) oint_S f_k(y) G_kj(y, x_i) dS(y),  G_kj = delta_kj / r + r_k r_j / r^3,
//   r = y - x_i,
//
// evaluated at every node x_i (the imposed flow u_inf is not included). f is the membrane force
// density given at the nodes and interpolated linearly over each triangle [43].
// - Triangles that do not contain x_i: the 7-point Gauss rule of degree 5 (Strang-Fix / Dunavant [117])
//   for every target (SingleLayerQuadrature::all7, the reference and the default), or (adaptive)
//   that rule only near the target and a cheaper one far from it, chosen per (target, cluster):
//     * the triangles are sorted by the Morton key of their centroids and cut into clusters of
//       `cluster_size` consecutive triangles (spatially compact); cluster c has centre c_c (mean of
//       its triangles' centroids) and radius rho_c (largest distance from c_c to a corner);
//     * far rule of a cluster: one point per triangle, its centroid z_t, with vector weights W_t =
//       W0_t + dW_t, W0_t = A_t mean(f) (the centroid rule, exact for the density's integral) and
//       dW the least-norm correction that makes the cluster's moments
//       sum_t m((z_t - c_c)/rho_c) W_t = sum_k m((y_k - c_c)/rho_c) w_k f_k
//       equal to those of its 7-point rule for every monomial m of degree <= `far_order` (1: 4
//       monomials; clusters with fewer triangles than monomials always use the 7-point rule);
//     * a target x_i uses the far rule for cluster c when |x_i - c_c| >= far_ratio * rho_c. By the
//       Taylor expansion of G about c_c, the far rule then differs from the 7-point rule by
//       O((rho_c / |x_i - c_c|)^(far_order + 1)) relative to the cluster's (absolute) contribution.
//   Measured (bench/bench_bim.cpp BM_QuadratureRatio, tests/flow/test_single_layer_adaptive.cpp),
//   as the difference max_i |u_adaptive(x_i) - u_all7(x_i)| / max_i |u_all7(x_i)|, with Method C's
//   bending force density, one thread: on the 5120-triangle red blood cell and 2:1:0.5 ellipsoid
//   the defaults (32, 1, 4) give 4e-5 to 1.2e-4 at 1.1 to 1.5 times the speed of all7 (wall clock,
//   shared machine; at 1280 triangles they are slower than all7, 0.85 times); a bound of 1e-5
//   needs (cluster_size, far_order, far_ratio) = (64, 4, 6) (2e-6 and 7e-6) or (32, 1, 10), where
//   the gain is 1.2 times at most: with a cluster's far zone beginning 6 to 10 radii away, most of
//   a 5120-triangle capsule is near every cluster, and the 7-point rule dominates. The adaptive rule
//   therefore is not the default (a hierarchical, treecode-like far field would be needed).
//   Every cluster that contains a corner at x_i lies within rho_c of x_i, so far_ratio > 1 keeps
//   the triangles at x_i on the 7-point rule, which the singular correction below takes back.
//   (tree) a hierarchical far field:
//     * clusters: a binary tree over the faces, halving each range until it holds at most
//       `tree_leaf_size` faces; per evaluation the faces are sorted by Morton key and then split
//       top down at the median centroid along the widest extent of the cluster's centroids (a k-d
//       tree: compact clusters whatever the shape). Cluster j has a box along the principal axes
//       of its triangle corners, centre c_j, half widths h_j, radius rho_j = |h_j|;
//     * far field of a cluster: the kernel G(y, x) is interpolated in y over the box by a
//       polynomial of total degree q = `tree_order` in the Chebyshev basis T_a T_b T_c (a + b + c
//       <= q), at m = (q + 1)(q + 2)(q + 3)/6 proxy points (approximate Fekete points picked once
//       by column-pivoted QR from a tensor Chebyshev grid in [-1, 1]^3, mapped to the box; 120 for
//       q = 7). Proxy weights W_m = sum_k L_m(y_k) w_k f_k (L_m the Lagrange basis at the proxies)
//       come from the Chebyshev moments of the cluster's 7-point points (leaves) or of its
//       children's proxies, which carry their moments of degree <= q exactly (a polynomial of
//       degree <= q in the parent's box is one in the child's), so each level costs O(m^2);
//       clusters whose proxies would be more than half their 7-point points keep those points;
//     * a node x_i uses cluster j's proxies when |x_i - c_j| >= d_j, d_j = max(tree_ratio rho_j,
//       (A_j rho_j^(q+1) / (tau U))^(1/(q+2))), A_j = sum |w_k f_k| over the cluster, U = sum |w_k f_k|
//       over the surface / (half diagonal of its bounding box), tau = `tree_tolerance`; else it
//       descends, and near leaves sum the 7-point rule (consecutive ranges in one call). The Taylor
//       remainder of G about c_j bounds the interpolation error of a cluster's contribution by
//       about A_j (rho_j / d)^(q+1) / d times the Lebesgue constant of the proxies, so the
//       acceptance keeps each accepted cluster's error below about tau U, at most tree_ratio
//       (> 1) box radii away, which keeps every node off the far field of its own triangles.
//   Measured (tests/flow/test_single_layer_tree.cpp; bench: ./build/release/bench_bim
//   --benchmark_filter='BM_QuadratureRatio/.*_tree/triangles:(1280|5120)/' --benchmark_min_time=2)
//   with the defaults (32, 7, 1.5, 2e-6), max_i |u_tree - u_all7| / max_i |u_all7|: 1.2e-6 (red
//   blood cell) and 2.8e-7 (ellipsoid) at 1280 triangles, 2.2e-6 and 4.4e-7 at 5120. Speed-up over
//   all7 (wall clock, one run each, on a shared 2-core machine with a load average of 6): at 5120
//   triangles 1.14 (red blood cell) and 1.47 (ellipsoid) on one thread, 1.19 and 1.25 on two; at
//   1280 the tree is slower (0.6 to 0.7). At 5120 each node sums about 8500 7-point and 6100
//   proxy points instead of 35840 (counted with tree_tolerance 3e-6 and leaves of 16), so the
//   sums alone would be about 2.4 times faster; the rest is
//   the set-up (moments about 12 %, boxes 5 %), the traversal and the polar integrals (together
//   about 20 %). The 3x target at 1e-5 is not reached at 5120 triangles; the rule is not the default.
//   Tried on an AMD EPYC with AVX2 (5120 triangles, Method C's density, one thread, processor
//   time, best of three; bench_bim --benchmark_filter=BM_TreeParameters repeats the scan in wall
//   time): the parameters around the defaults are a flat optimum, speed-up over
//   all7 (red blood cell / ellipsoid) 1.50 / 1.71 at the defaults, 1.39-1.53 / 1.57-1.79 with
//   leaves of 16 to 64 or degree 6 or 8, 1.61 / 1.82 with tolerance 4e-6 (difference 4.2e-6).
//   The regular sums are 64 % of the time (perf), the moments 12 %. 1/r from the single-precision
//   reciprocal square root and two Newton steps in double (AVX2 intrinsics, relative error about
//   1e-13) instead of the square root and division was slower there (an experiment, not kept),
//   all7 164 ms against 142 ms:
//   the kernel trades the divider's throughput for the multiply-add ports, which are then full.
//   Not tried: target clusters sharing one traversal, a cheaper rule for near triangles a few edge
//   lengths away (the 7-point sums are now over half the work).
//   (tree_mixed, "tree-mixed") the same tree and the same terms, with the regular sums (the near
//   leaves' 7-point points and the far clusters' proxies) in single precision: eight lanes of
//   AVX2 instead of four, and the single-precision square root and division, which have more
//   than twice the throughput of the double ones that bound the double kernel. What makes it
//   accurate: each leaf's points and each cluster's proxies are kept relative to their box
//   centre (|y - c_j| <= rho_j), and the target's offset from that centre is formed in double
//   before it is rounded, so every difference y_k - x_i carries an absolute error of about
//   2^-24 rho_j (about 1e-6 relative for the nearest points of a 5120-triangle capsule, far less
//   for the rest); each leaf or cluster is summed on its own (at most a few hundred terms,
//   16 partial sums in float), and those sums are added in double. The ring triangles' 7-point
//   terms, which the polar rule replaces, are taken back in double: their single-precision
//   values differ by that relative error. Measured in the tests (tests/flow/
//   test_single_layer_mixed.cpp), max_i |u - u_ref| / max_i |u_ref|: 2.4e-7 (red blood cell) and
//   1.6e-7 (ellipsoid) from the double tree at 1280 triangles, 2.2e-7 from all7 with no far field
//   (every face by the 7-point rule in single precision); from all7 with the defaults 1.2e-6 /
//   3.6e-7 at 1280 and 2.2e-6 / 4.6e-7 at 5120 triangles (the tree's own 1.2e-6 / 2.8e-7 and
//   2.2e-6 / 4.4e-7).
//   Speed-up over all7 (bench_bim --benchmark_filter='BM_QuadratureRatio/.*_tree(_mixed)?/
//   triangles:(1280|5120)/threads:1' --benchmark_min_time=2; AMD EPYC with AVX2, one thread, the
//   background runs stopped; the moments by the vector kernel of chebyshev_moments.hpp in both):
//   at 5120 triangles tree-mixed 2.16 (red blood cell) / 2.35 (ellipsoid), tree 1.53 / 1.75; at
//   1280 tree-mixed 1.03 / 1.10, tree 0.83 / 0.88. Before the moments kernel (same run otherwise):
//   tree-mixed 1.80 / 2.00, tree 1.42 / 1.57. perf of one tree-mixed evaluation at 5120: the sums
//   52 %, the traversal, the ring correction and the polar integrals (velocity()) 22 % and their
//   sines and cosines 4 %, the moments 8 %, the boxes 5 %.
//   On an Intel Xeon with AVX-512 the sums were 69 % of an evaluation, and half of that was the
//   scalar remainder loop: a leaf of 20 faces has 140 points, 8 vectors of 16 floats and 12
//   points one at a time, and a cluster's 120 proxies leave 8. So the kernel now takes all the
//   ranges of one node (near leaves and far clusters) in one call, each range padded with zero
//   weights to whole blocks of 16 points (a leaf's padding sits at its first point, a cluster's
//   at its centre, which its targets are far from), summed in 16 float lanes per range that are
//   added to 16 double lanes, reduced once per node. Same bench command, that machine, one
//   thread, the study's two runs on the two cores: tree-mixed 3.92 (red blood cell) / 3.70
//   (ellipsoid) times all7 at 5120 triangles (1.62 / 1.59 at 1280), differences from all7 as
//   before (2.2e-6 / 4.5e-7); thread processor time: 3.71 / 4.04. The double tree: 1.89 / 2.10.
//   With the clones for x86-64-v4 left out (so the AVX2 clone runs, same machine, processor
//   time): 3.48 / 3.81, and 3.33 / 3.62 before the padding. perf of one evaluation now: the sums
//   52 %, traversal, ring correction and polar integrals 19 % (sines and cosines 3 %), moments
//   9 %, boxes 8 %.
// - Triangles that contain x_i: polar coordinates (rho, phi) centred on x_i [118]. There
//   G dS = (I + e e^T) / rho * rho drho dphi, the singularity cancels, and with f linear along
//   each ray the radial integral is exact: int_0^rho_max f drho = rho_max (f(x_i) + f_edge(phi)) / 2.
//   The angle is integrated by Gauss-Legendre on `angular_subdivisions` equal sub-angles
//   (sub-triangles at the singular vertex) of `angular_points` points each.
// All quadrature points, weights and interpolated densities are precomputed once per evaluation
// in structure-of-arrays form; the loop over targets runs in parallel (OpenMP).
// Where the parts are: triangle_quadrature.hpp the 7-point and Gauss-Legendre rules;
// singular_polar_integral.hpp the triangles at the target; stokeslet_sums.hpp the regular sums
// (double and single precision); single_layer_adaptive.cpp, single_layer_tree.cpp and
// single_layer_mixed.cpp each rule's set-up and per-target traversal; stokes_single_layer.cpp the
// options, the 7-point points of an evaluation and velocity().
#include <cstdint>
#include <string>
#include <vector>

#include "bendlab/core/types.hpp"
#include "bendlab/flow/bim/triangle_quadrature.hpp"
#include "bendlab/mesh/topology.hpp"

namespace bendlab {

struct MixedRange;  // stokeslet_sums.hpp

/// all7: the 7-point rule on every non-singular triangle for every target (the reference, default);
/// adaptive: the 7-point rule near the target, the moment-corrected centroid rule far from it;
/// tree: the 7-point rule near the target, Chebyshev proxies of a cluster tree far from it;
/// tree_mixed: the tree with its regular sums in single precision (summed in double).
enum class SingleLayerQuadrature { all7, adaptive, tree, tree_mixed };

struct SingleLayerOptions {
  int angular_points = 8;        ///< Gauss-Legendre points per sub-angle of a singular triangle
  int angular_subdivisions = 2;  ///< sub-angles per singular triangle
  SingleLayerQuadrature quadrature = SingleLayerQuadrature::all7;
  int cluster_size = 32;   ///< adaptive: triangles per cluster (>= 1)
  int far_order = 1;       ///< adaptive: the far rule matches the cluster's moments up to this degree (0..4)
  double far_ratio = 4.0;  ///< adaptive: far when |x_i - c_c| >= far_ratio * rho_c (> 1)
  int tree_leaf_size = 32;  ///< tree: at most this many triangles per leaf cluster (>= 1)
  int tree_order = 7;       ///< tree: the proxies interpolate the kernel to this total degree (0..8)
  double tree_ratio = 1.5;  ///< tree: far only when |x_i - c_j| >= tree_ratio * rho_j (> 1)
  double tree_tolerance = 2e-6;  ///< tree: and when the far field's error estimate is below this (>= 0)
};

/// "all7" | "adaptive" | "tree" | "tree-mixed"; the inverse throws bendlab::Error naming the unknown value.
std::string to_string(SingleLayerQuadrature q);
SingleLayerQuadrature single_layer_quadrature(const std::string& name);

class StokesSingleLayer {
 public:
  explicit StokesSingleLayer(TopologyPtr topology, SingleLayerOptions options = {});

  /// u (N x 3, resized if needed) = single-layer velocity at every node for node positions x and
  /// node force densities f_density (both N x 3), viscosity mu. Not for concurrent use of one object.
  void velocity(const Points& x, const Points& f_density, double mu, Points& u) const;

  const Topology& topology() const { return *topology_; }
  const SingleLayerOptions& options() const { return options_; }

 private:
  void prepare(const Points& x, const Points& f) const;
  /// adaptive (single_layer_adaptive.cpp): the clusters' centres, radii and far weights; a
  /// target's regular sum (u[0..2]).
  void prepare_adaptive(const Points& x) const;
  void adaptive_sum(double xi, double yi, double zi, double* u) const;
  /// tree (single_layer_tree.cpp): the clusters and the proxies' reference points and Lagrange
  /// basis (once); the k-d refinement of the sorted faces, the boxes and proxies (per
  /// evaluation); a target's regular sum.
  void build_tree();
  void refine_tree_order(const Points& x) const;
  void prepare_tree(const Points& x) const;
  void tree_sum(double xi, double yi, double zi, double* u) const;
  /// tree_mixed (single_layer_mixed.cpp): where the leaves' points and the clusters' proxies go
  /// in the float arrays (once), their single-precision copies (per evaluation), a target's
  /// regular sum with `ranges` for its leaves and clusters.
  void layout_single_precision();
  void prepare_single_precision() const;
  void mixed_sum(double xi, double yi, double zi, std::vector<MixedRange>& ranges, double* u) const;
  bool tree() const {
    return options_.quadrature == SingleLayerQuadrature::tree || options_.quadrature == SingleLayerQuadrature::tree_mixed;
  }

  TopologyPtr topology_;
  SingleLayerOptions options_;
  std::vector<double> gl_nodes_, gl_weights_;  // Gauss-Legendre on [0, 1]
  // Per-evaluation buffers (prepared once per call, reused between calls).
  // slot_[k]: the face at sorted position k (all7: k itself); position_[face] its inverse.
  mutable std::vector<int> slot_, position_;
  mutable std::vector<std::uint64_t> keys_;
  // 7-point quadrature points (7 per face, in sorted order) and density times weight times area.
  mutable std::vector<double> qx_, qy_, qz_, fx_, fy_, fz_;
  // adaptive: far-rule points (one per face, sorted order) and weights; clusters' centres, radii
  // squared times far_ratio^2, and whether the far rule may be used.
  mutable std::vector<double> px_, py_, pz_, pfx_, pfy_, pfz_;
  mutable std::vector<double> cx_, cy_, cz_, far2_;
  // tree: clusters in breadth-first order (the root first; the children of a cluster are
  // consecutive), each the range [tree_begin_, tree_end_) of sorted faces, its first child (-1: a
  // leaf), its proxy slot (-1: none) and the first cluster of each depth. Built once.
  std::vector<int> tree_begin_, tree_end_, tree_child_, tree_proxy_, tree_level_;
  // Degrees (a, b, c) of the Chebyshev basis, reference proxies in [-1, 1]^3 (x, y, z each) and
  // the Lagrange basis at them in the Chebyshev basis (C(beta, m) at beta * count + m).
  std::vector<int> tree_basis_;
  std::vector<double> tree_reference_, tree_lagrange_;
  // Per evaluation: box centres, far distance squared, proxy counts (0: none) and the proxies.
  mutable std::vector<int> tree_count_;
  mutable std::vector<double> bcx_, bcy_, bcz_, tree_far2_;
  mutable std::vector<double> tpx_, tpy_, tpz_, tfx_, tfy_, tfz_;
  // tree_mixed: in single precision, each leaf's 7-point points relative to its box centre and
  // each cluster's proxies relative to its own, with their weights, in one set of arrays; each
  // range padded with zero weights to a whole number of kernel blocks (kMixedBlock points), so
  // that the kernel has no remainder loop. mixed_leaf_[j] and mixed_proxy_[j]: where cluster j's
  // points and proxies begin (-1: none); mixed_leaf_count_[j]: its padded point count. Built once.
  std::vector<int> mixed_leaf_, mixed_leaf_count_, mixed_proxy_;
  int mixed_proxy_count_ = 0;
  mutable std::vector<float> mx_, my_, mz_, mfx_, mfy_, mfz_;
};

}  // namespace bendlab
