#pragma once
// The least-squares solve of Method M's jet (METHOD_M.md steps 3-4) for kJetLanes nodes side by
// side: lane l of every array below belongs to node l, so each arithmetic step is one SIMD
// instruction across the nodes (no shuffles), in place of the per-node fixed-size Eigen solve
// whose Cholesky and triangular solves ran one element at a time. The per-node reference is
// monge_jet_fit_point (monge_jet.hpp), which tests hold this against.
//
// For each lane, with samples (xi_j, eta_j, h_j, w_j) (scaled chart coordinates, height, weight),
// the normal equations sum_j w_j phi_j phi_j^T c = sum_j w_j h_j phi_j of the basis
// phi = (xi^a eta^b, 1 <= a + b <= degree) are summed from the moments sum_j w_j xi^p eta^q,
// factored by Cholesky and solved. A lane whose factor fails the pivot test
// min_k L_kk^2 > kJetMinPivotRatio max_k M_kk (a support that does not determine the jet) is
// reported as not determined, its coefficients left unspecified.
#include <vector>

namespace bendlab {

inline constexpr int kJetLanes = 8;
/// See kMinPivotRatio in monge_jet.cpp, the reference's test, which uses the same value.
inline constexpr double kJetMinPivotRatio = 1e-12;

/// Samples of kJetLanes fits, lane-interleaved: sample j of lane l at [j * kJetLanes + l]. Lanes
/// with fewer samples are padded with weight 0 (which adds nothing to any sum).
struct JetLaneSamples {
  int count = 0;  ///< samples per lane, padding included
  std::vector<double> xi, eta, height, weight;
  /// count samples per lane, all zero (weight 0).
  void reset(int count);
};

/// Coefficients c_k of every lane at coefficients[k * kJetLanes + l] (k < unknowns of `degree`, in
/// the basis order of monge_jet.cpp: by total degree, then by the power of eta); determined[l] is
/// the pivot test's verdict. degree 4, 5 or 6.
/// With inv_scale (1/s of each lane's chart) and laplacian_y (room for as many values as the
/// coefficients), also y = M^-1 l with the same factor, l the Laplace-Beltrami operator of the
/// lane's fitted graph at its node applied to a jet's coefficients (monge_jet_laplacian): the
/// operator's weight on sample j of a field is then w_j phi_j . y (Method M's laplacian = field,
/// at the cost of one more pair of triangular solves).
void solve_jet_lanes(int degree, const JetLaneSamples& samples, double* coefficients, bool* determined,
                     const double* inv_scale = nullptr, double* laplacian_y = nullptr);

}  // namespace bendlab
