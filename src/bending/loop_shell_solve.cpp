#include "bendlab/bending/loop_shell_solve.hpp"

#include <string>

#include "bendlab/core/types.hpp"

namespace bendlab::loop_shell {

namespace {

// q = M p for symmetric column-major M: row i of M is its column i. One pass over M's entries
// for all columns of p at once (K of them; K = 0: p.cols() at run time).
template <int K>
void symmetric_product_k(const Eigen::SparseMatrix<double>& m, const Eigen::MatrixXd& p, Eigen::MatrixXd& q,
                         int parallel_rows) {
  const int n = static_cast<int>(m.cols());
  const int k = K > 0 ? K : static_cast<int>(p.cols());
  const int* outer = m.outerIndexPtr();
  const int* inner = m.innerIndexPtr();
  const double* values = m.valuePtr();
  const double* pc = p.data();
  double* qc = q.data();
#pragma omp parallel for schedule(static) if (n > parallel_rows)
  for (int i = 0; i < n; ++i) {
    if constexpr (K > 0) {
      double s[K] = {};
      for (int e = outer[i]; e < outer[i + 1]; ++e) {
        const double v = values[e];
        const int j = inner[e];
        for (int c = 0; c < K; ++c) s[c] += v * pc[j + c * n];
      }
      for (int c = 0; c < K; ++c) qc[i + c * n] = s[c];
    } else {
      for (int c = 0; c < k; ++c) {
        double s = 0.0;
        for (int e = outer[i]; e < outer[i + 1]; ++e) s += values[e] * pc[inner[e] + c * n];
        qc[i + c * n] = s;
      }
    }
  }
}

void symmetric_product(const Eigen::SparseMatrix<double>& m, const Eigen::MatrixXd& p, Eigen::MatrixXd& q,
                       int parallel_rows) {
  switch (p.cols()) {
    case 1: symmetric_product_k<1>(m, p, q, parallel_rows); break;
    case 3: symmetric_product_k<3>(m, p, q, parallel_rows); break;
    case 4: symmetric_product_k<4>(m, p, q, parallel_rows); break;
    default: symmetric_product_k<0>(m, p, q, parallel_rows); break;
  }
}

}  // namespace

Eigen::MatrixXd solve_mass_cg(const Eigen::SparseMatrix<double>& m, const Eigen::MatrixXd& b, double tolerance,
                              int max_iterations, int* iterations, const Eigen::MatrixXd* x0,
                              int parallel_rows) {
  CgBuffers buffers;
  Eigen::MatrixXd x;
  solve_mass_cg(m, b, tolerance, max_iterations, iterations, x0, parallel_rows, buffers, x);
  return x;
}

void solve_mass_cg(const Eigen::SparseMatrix<double>& m, const Eigen::MatrixXd& b, double tolerance, int max_iterations,
                   int* iterations, const Eigen::MatrixXd* x0, int parallel_rows, CgBuffers& buffers,
                   Eigen::MatrixXd& x) {
  const Eigen::Index n = b.rows(), k = b.cols();
  Eigen::VectorXd& inv_diag = buffers.inv_diag;
  Eigen::MatrixXd &r = buffers.r, &z = buffers.z, &p = buffers.p, &q = buffers.q;
  Eigen::RowVectorXd &rz = buffers.rz, &limit = buffers.limit, &res = buffers.res;
  inv_diag = m.diagonal().cwiseInverse();
  const bool warm = x0 && x0->rows() == n && x0->cols() == k;
  if (warm)
    x = *x0;
  else
    x.setZero(n, k);
  r = b;
  if (warm) {
    Eigen::MatrixXd& mx = buffers.mx;
    mx.resize(n, k);
    symmetric_product(m, x, mx, parallel_rows);
    r -= mx;
  }
  z.noalias() = inv_diag.asDiagonal() * r;
  p = z;
  q.resize(n, k);
  rz = (r.cwiseProduct(z)).colwise().sum();
  limit = tolerance * b.colwise().norm();
  int it = 0;
  while (true) {
    res = r.colwise().norm();
    if ((res.array() <= limit.array()).all()) break;
    if (it == max_iterations)
      throw Error("method S: the mass-matrix solve did not converge in " + std::to_string(max_iterations) +
                  " CG iterations");
    ++it;
    symmetric_product(m, p, q, parallel_rows);
    for (Eigen::Index c = 0; c < k; ++c) {
      if (res[c] <= limit[c]) continue;  // converged column: leave it
      const double alpha = rz[c] / p.col(c).dot(q.col(c));
      x.col(c) += alpha * p.col(c);
      r.col(c) -= alpha * q.col(c);
    }
    z.noalias() = inv_diag.asDiagonal() * r;
    for (Eigen::Index c = 0; c < k; ++c) {
      const double rz_new = r.col(c).dot(z.col(c));
      const double beta = rz[c] > 0 ? rz_new / rz[c] : 0.0;
      p.col(c) = z.col(c) + beta * p.col(c);
      rz[c] = rz_new;
    }
  }
  if (iterations) *iterations = it;
}

}  // namespace bendlab::loop_shell
