#include "bendlab/bending/loop_shell_solve.hpp"

#include <string>

#include "bendlab/core/types.hpp"

namespace bendlab::loop_shell {

Eigen::MatrixXd solve_mass_cg(const Eigen::SparseMatrix<double>& m, const Eigen::MatrixXd& b, double tolerance,
                              int max_iterations, int* iterations) {
  const Eigen::Index n = b.rows(), k = b.cols();
  const Eigen::VectorXd inv_diag = m.diagonal().cwiseInverse();
  Eigen::MatrixXd x = Eigen::MatrixXd::Zero(n, k), r = b;
  Eigen::MatrixXd z = inv_diag.asDiagonal() * r, p = z, q(n, k);
  Eigen::RowVectorXd rz = (r.cwiseProduct(z)).colwise().sum();
  const Eigen::RowVectorXd limit = tolerance * b.colwise().norm();
  int it = 0;
  while (true) {
    const Eigen::RowVectorXd res = r.colwise().norm();
    if ((res.array() <= limit.array()).all()) break;
    if (it == max_iterations)
      throw Error("method S: the mass-matrix solve did not converge in " + std::to_string(max_iterations) +
                  " CG iterations");
    ++it;
    q.noalias() = m * p;
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
  return x;
}

}  // namespace bendlab::loop_shell
