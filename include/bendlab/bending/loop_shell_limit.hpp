#pragma once
// Method S (paper section 2.5): values at the limit points of the nodes (METHOD_S.md sections
// 2 and 4.2).
//
//   limit position  x_i = (1 - N chi) P_i + chi sum_ring P_j, chi = 1 / (N + 3 / (8 beta_N));
//   tangents        t1 = sum_j cos(2 pi j / N) P_j, t2 = sum_j sin(2 pi j / N) P_j over the
//                   counter-clockwise ring; n_i = t1 x t2 / |t1 x t2| (outward);
//   H, K            at a regular node: one incident patch evaluated at its corner; at an
//                   extraordinary node (valence != 6) they are not defined at the point itself
//                   (the surface is only C1 there): the mean over the incident patches at
//                   v = w = 1e-3 (the EV corner is u = 1) is reported.
#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>
#include <map>
#include <utility>

#include "bendlab/bending/loop_shell_basis.hpp"
#include "bendlab/bending/loop_shell_patches.hpp"
#include "bendlab/core/types.hpp"
#include "bendlab/mesh/topology.hpp"

namespace bendlab::loop_shell {

/// Distance (in v = w) from an extraordinary node at which its H and K are sampled.
inline constexpr double kExtraordinarySample = 1e-3;

/// The limit-mask matrix L (N x N, row i: 1 - N_i chi at i, chi at each ring vertex), so that
/// L P gives the limit points of control points P. Rows sum to 1.
Eigen::SparseMatrix<double> limit_matrix(const Topology& topology);

/// Solves L P = X for the control points P whose limit points are X. L = C S with C = diag(chi_i)
/// and S symmetric (S_ij = 1 for ring neighbours, S_ii = 1 / chi_i - N_i); S is positive definite
/// (C^1/2 S C^1/2 is similar to L, whose eigenvalues lie in [1/4, 1]), so P = S^-1 C^-1 X by a
/// sparse LDL^T of S, factorised once per topology. Equal to an LU solve of L to round-off (tested).
class LimitSolver {
 public:
  explicit LimitSolver(const Topology& topology);
  Points solve(const Points& x) const;
  /// The same into p (resized), with the buffers `rhs` and `work`: the same arithmetic as
  /// Eigen's SimplicialLDLT::solve, whose in-place permutations would allocate at every call.
  void solve(const Points& x, Points& p, Eigen::MatrixXd& rhs, Eigen::MatrixXd& work) const;

 private:
  Eigen::VectorXd inv_chi_;
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt_;
  Eigen::VectorXd inv_d_;  ///< 1 / D of the factorisation (vectorD() returns a copy)
};

/// Outward unit normals of the limit surface at the limit points of the nodes.
Points limit_normals(const Topology& topology, const Points& control);
/// The same into `normal` (resized).
void limit_normals(const Topology& topology, const Points& control, Points& normal);

/// The patch bases limit_curvatures evaluates: they depend on the connectivity only, so a caller
/// evaluating many shapes of one mesh builds them once (Method S keeps them per topology).
struct LimitCurvatureBases {
  /// (valence of the patch, local corner 0 / 1 / 2): the basis at u = 1, v = 1 or w = 1.
  std::map<std::pair<int, int>, PatchBasis> corner;
  /// Valence of an extraordinary node: the basis at v = w = kExtraordinarySample.
  std::map<int, PatchBasis> near_ev;
  static LimitCurvatureBases build(const Topology& topology, const LoopPatches& patches);
};

/// H and K of the limit surface at the nodes' limit points (see the header comment).
void limit_curvatures(const Topology& topology, const LoopPatches& patches, const Points& control, Scalars& H,
                      Scalars& K);
/// The same with the bases built beforehand (no allocation when H and K have the size).
void limit_curvatures(const Topology& topology, const LoopPatches& patches, const LimitCurvatureBases& bases,
                      const Points& control, Scalars& H, Scalars& K);

}  // namespace bendlab::loop_shell
