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
/// another shape), to |B_c - M X_c| <= tolerance |B_c| per column. The products M p run over the
/// OpenMP threads from parallel_rows rows on (row i from column i, M being symmetric: no conflicts,
/// thread-count independent).
/// `iterations` (if not null) receives the count. Throws bendlab::Error if max_iterations do not
/// suffice. M must be symmetric positive definite with both triangles stored.
Eigen::MatrixXd solve_mass_cg(const Eigen::SparseMatrix<double>& m, const Eigen::MatrixXd& b, double tolerance,
                              int max_iterations, int* iterations = nullptr, const Eigen::MatrixXd* x0 = nullptr,
                              int parallel_rows = 2000);

/// The iteration's vectors, kept by a caller that solves again and again (Method S's workspace).
struct CgBuffers {
  Eigen::VectorXd inv_diag;
  Eigen::MatrixXd r, mx, z, p, q;
  Eigen::RowVectorXd rz, limit, res;
};
/// The same solve into x (resized), with the buffers of `buffers`: no allocation once they have
/// the sizes of M and B. x0 must not be x.
void solve_mass_cg(const Eigen::SparseMatrix<double>& m, const Eigen::MatrixXd& b, double tolerance, int max_iterations,
                   int* iterations, const Eigen::MatrixXd* x0, int parallel_rows, CgBuffers& buffers,
                   Eigen::MatrixXd& x);

}  // namespace bendlab::loop_shell
