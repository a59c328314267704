#pragma once
// Method S (paper section 2.5): differential geometry of the Loop limit surface at quadrature
// points, the Helfrich energy E_B = 2 kB int H^2 dA and its exact gradient with respect to the
// control points (METHOD_S.md section 3).
//
// With theta = (v, w) and I over a patch's control points P_I:
//   a_alpha = sum N_I,alpha P_I, metric a_ab = a_a . a_b, dual a^a = a^ab a_b,
//   J = |a_1 x a_2|, n = a_1 x a_2 / J (outward: patches are counter-clockwise),
//   b_ab = n . x_,ab, H = -1/2 a^ab b_ab (> 0 on a sphere, docs/conventions.md), K = det b / det a;
//   dJ/dP_I = J N_I,a a^a,
//   dH/dP_I = b^ab N_I,b a_a - 1/2 a^ab (N_I,ab - Gamma^g_ab N_I,g) n, Gamma^g_ab = a^g . x_,ab,
//   dE_B/dP_I = 2 kB sum_T sum_q w_q [2 H J dH/dP_I + H^2 dJ/dP_I],
// w_q = rule weight / 2 (the (v, w) triangle has area 1/2).
#include <vector>

#include "bendlab/bending/loop_shell_basis.hpp"
#include "bendlab/bending/loop_shell_patches.hpp"
#include "bendlab/core/types.hpp"

namespace bendlab::loop_shell {

/// The energy's coefficients: kB, and for c0 and ADE (docs/conventions.md §5) the spontaneous
/// curvature and lambda = alpha pi kB (M - M0) / A (BendingParameters::ade_lambda) at the current
/// shape, held fixed over one evaluation: E = 2 kB int (H - c0)^2 dA (+ E_ADE, added by the caller)
/// and
///   dE/dP_I = sum_T sum_q w_q [(4 kB (H - c0) + lambda) J dH/dP_I + (2 kB (H - c0)^2 + lambda H) dJ/dP_I].
/// A plain kB (implicit conversion) takes the c0 = 0 expressions of the header unchanged.
struct ShellTerms {
  double kappa_b = 1.0;
  double c0 = 0.0;
  double lambda = 0.0;
  bool plain = true;
  ShellTerms(double kappa_b) : kappa_b(kappa_b) {}  // NOLINT(google-explicit-constructor)
  ShellTerms(double kappa_b, double c0, double lambda) : kappa_b(kappa_b), c0(c0), lambda(lambda), plain(false) {}
};

/// The basis of every patch valence at every point of a quadrature rule (patch-local (v, w)).
/// The rules are symmetric, so the same points serve whichever corner a patch starts at.
class QuadratureBases {
 public:
  QuadratureBases(TriangleRule rule, const std::vector<int>& valences);
  const TriangleRule& rule() const { return rule_; }
  /// Bases at the rule's points for patches of EV valence n (one of the valences given).
  const std::vector<PatchBasis>& at(int valence) const;
  /// The products N_a N_b of the shape functions at the rule's points for valence n: row k for
  /// the k-th pair a <= b of the upper triangle read row by row, column q for point q; so that a
  /// patch's mass block is this matrix times (w_q J_q / 2) (face_energy_fast).
  const Eigen::MatrixXd& mass_products(int valence) const;

 private:
  TriangleRule rule_;
  std::vector<std::vector<PatchBasis>> by_valence_;  // index: valence
  std::vector<Eigen::MatrixXd> mass_products_;      // index: valence
};

/// The limit surface at one parameter point of one patch.
struct SurfacePoint {
  Vec3 x, a1, a2, n;
  double J = 0, H = 0, K = 0;
};
/// Evaluates position, tangents, normal, area element J, H and K from the patch basis at the
/// point and the control points (idx: the patch's local -> global indices).
SurfacePoint surface_point(const PatchBasis& basis, const Points& control, const int* idx);

/// One patch's share: its E_B and, in `local` (if not null), its rows of dE_B/dP (patch order),
/// and, when asked, its block of the mass matrix int N_a N_b dA and int N_a H dA, all from one
/// evaluation of the surface per quadrature point.
struct FaceLocal {
  bool with_mass = false, with_h = false;
  Eigen::Matrix<double, Eigen::Dynamic, 3> gradient;
  Eigen::MatrixXd mass;
  Eigen::VectorXd h;
};
double face_energy(const std::vector<PatchBasis>& basis, const TriangleRule& rule, const Points& control,
                   const int* idx, const ShellTerms& terms, FaceLocal* local);

/// What face_energy_fast returns for one patch of m = N + 6 control points: its rows of dE_B/dP
/// (patch order), its mass block int N_a N_b dA as the upper triangle (pairs a <= b, row by row)
/// and int N_a H dA.
struct FaceWork {
  /// Largest patch with a fixed-size kernel: EV valence 3 .. kMaxFastValence.
  static constexpr int kMaxFastValence = 8;
  static constexpr int kMax = kMaxFastValence + 6;
  int m = 0;
  double gradient[kMax][3];
  double mass[kMax * (kMax + 1) / 2];
  double h[kMax];
};
/// The same sums as face_energy (the reference; equal to round-off, tested) for a patch of EV
/// valence 3 .. FaceWork::kMaxFastValence: fixed-size products on the tabulated bases, the mass
/// block from QuadratureBases::mass_products, no heap allocation. Returns false (and does
/// nothing) for another valence. Adds the patch's E_B to `energy`; h only if with_h.
bool face_energy_fast(const QuadratureBases& bases, int valence, const Points& control, const int* idx,
                      const ShellTerms& terms, bool with_h, FaceWork& work, double& energy);

/// E_B = 2 kB int H^2 dA over the limit surface with the rule of `bases`; if gradient is not
/// null it is resized to P's shape and receives dE_B/dP (so F = -gradient).
double shell_energy(const LoopPatches& patches, const QuadratureBases& bases, const Points& control,
                    const ShellTerms& terms, Points* gradient);

/// Surface area of the limit surface, int dA, with the same rule.
double shell_area(const LoopPatches& patches, const QuadratureBases& bases, const Points& control);

/// M = int H dA over the limit surface with the same rule (the ADE term, docs/conventions.md §5).
double shell_mean_curvature_integral(const LoopPatches& patches, const QuadratureBases& bases, const Points& control);

}  // namespace bendlab::loop_shell
