#pragma once
// Method S: the mass-matrix solve M f_c = F_c (METHOD_S.md section 4.1). M is symmetric
// positive definite and well conditioned (cond 71-111 on the MT1 RBC, 320-5120 triangles), so
// Jacobi-preconditioned conjugate gradients converge in a slowly growing number of iterations
// (O(N) each), far cheaper than a sparse factorisation of M, whose fill-in grows fast (the
// paper used GMRES to 1e-9).
#include <Eigen/Sparse>

namespace bendlab::loop_shell {

/// Solves M X = B for every column of B at once (one pass over M per iteration) with
/// Jacobi-preconditioned CG from X = x0 (a previous solution: warm start; zero if null or of
/// another shape), to |B_c - M X_c| <= tolerance |B_c| per column; a converged column is left as it
/// is while the others go on. The work runs over the OpenMP threads from parallel_rows rows on,
/// thread-count independent (rows of M from its columns, M being symmetric; sums in a fixed order).
/// `iterations` (if not null) receives the count. Throws bendlab::Error if max_iterations do not
/// suffice. M must be symmetric positive definite with both triangles stored.
///
/// Up to 4 columns (Method S's 3 force components, and H's projection): the columns interleaved
/// row by row and padded to 4, so that each entry of M is read once per iteration with one
/// contiguous load of the 4 values it multiplies, and the vector updates fused into two passes
/// (loop_shell_solve.cpp). Measured on the 5120-triangle red blood cell, 60 iterations, one
/// thread (bench/loop_shell_stages): see docs/results/method_s_speed.md.
Eigen::MatrixXd solve_mass_cg(const Eigen::SparseMatrix<double>& m, const Eigen::MatrixXd& b, double tolerance,
                              int max_iterations, int* iterations = nullptr, const Eigen::MatrixXd* x0 = nullptr,
                              int parallel_rows = 2000);

/// The same iteration written plainly on Eigen's column-major matrices (the reference the fast
/// path is tested against; any number of columns). Iterates equal to rounding.
Eigen::MatrixXd solve_mass_cg_reference(const Eigen::SparseMatrix<double>& m, const Eigen::MatrixXd& b,
                                        double tolerance, int max_iterations, int* iterations = nullptr,
                                        const Eigen::MatrixXd* x0 = nullptr, int parallel_rows = 2000);

}  // namespace bendlab::loop_shell
