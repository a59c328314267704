#pragma once
// Chebyshev moments of point sources in a box, the set-up of the single layer's tree quadrature
// (stokes_single_layer.hpp, "tree"): for sources y_k with vector weights F_k,
//
//   M_beta = sum_k T_a(s_k,x) T_b(s_k,y) T_c(s_k,z) F_k,   s_k = S (y_k - centre),
//
// for every beta = (a, b, c) with a + b + c <= q, in the order a, then b, then c ascending
// (S maps the box to [-1, 1]^3; column-major 3 x 3). Both functions add to mx, my, mz (one entry
// per beta, (q + 1)(q + 2)(q + 3) / 6 of them).
//
// chebyshev_moments_reference: point by point, the sum over the points in their order.
// chebyshev_moments: the same terms with four points at a time in the lanes of one vector (the
// reference's inner loop runs over the at most q + 1 values of c and reads and writes the
// moments for every point; here they stay in four partial sums per moment, added at the end).
// Equal to the reference up to the order of the sum (tests/flow/test_chebyshev_moments.cpp).
// Measured in the tree's set-up at 5120 triangles, degree 7 (perf record of bench_bim
// --benchmark_filter=BM_SingleLayer/tree_mixed/triangles:5120/threads:1, AMD EPYC with AVX2): the
// reference's loop took 22 % of an evaluation, this kernel 8 % (the tree-mixed evaluation 1.2
// times faster, stokes_single_layer.hpp).
namespace bendlab {

void chebyshev_moments_reference(const double* S, const double* centre, int q, const double* sx, const double* sy,
                                 const double* sz, const double* sfx, const double* sfy, const double* sfz, int count,
                                 double* mx, double* my, double* mz);

void chebyshev_moments(const double* S, const double* centre, int q, const double* sx, const double* sy,
                       const double* sz, const double* sfx, const double* sfy, const double* sfz, int count,
                       double* mx, double* my, double* mz);

/// The number of moments of degree q (0 <= q <= 8): (q + 1)(q + 2)(q + 3) / 6.
constexpr int chebyshev_moment_count(int q) { return (q + 1) * (q + 2) * (q + 3) / 6; }

}  // namespace bendlab
