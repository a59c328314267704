#include "bendlab/bending/loop_shell_solve.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

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

// Fast path of solve_mass_cg: the columns interleaved row by row (padded to kWidth), so that one pass
// over M's entries serves every column with contiguous loads; the vector updates fused into two passes
// per iteration; dot products summed per fixed chunk of rows and then in chunk order, so the
// iterates do not depend on the thread count.
constexpr int kChunk = 512;

template <int kWidth>
Eigen::MatrixXd solve_mass_cg_interleaved(const Eigen::SparseMatrix<double>& m, const Eigen::MatrixXd& b,
                                          double tolerance, int max_iterations, int* iterations,
                                          const Eigen::MatrixXd* x0, int parallel_rows) {
  const int n = static_cast<int>(b.rows());
  constexpr int k = kWidth;
  const int chunks = (n + kChunk - 1) / kChunk;
  const bool parallel = n > parallel_rows;
  const int* outer = m.outerIndexPtr();
  const int* inner = m.innerIndexPtr();
  const double* values = m.valuePtr();
  std::vector<double> inv_diag(n);
  {
    const Eigen::VectorXd d = m.diagonal();
    for (int i = 0; i < n; ++i) inv_diag[i] = 1.0 / d[i];
  }
  const size_t size = static_cast<size_t>(n) * kWidth;
  std::vector<double> x(size, 0.0), r(size, 0.0), p(size, 0.0), q(size, 0.0);
  std::vector<double> partial(static_cast<size_t>(chunks) * 2 * kWidth);
  for (int i = 0; i < n; ++i)
    for (int c = 0; c < k; ++c) r[i * kWidth + c] = b(i, c);
  const bool warm = x0 && x0->rows() == n && x0->cols() == k;

  // out = M v, one pass over M (row i of the symmetric M is its column i); with `dot`, the chunks'
  // partial sums of v.out go to partial (first of the pair; the second is zero).
  auto product = [&](const std::vector<double>& v, std::vector<double>& out, bool dot) {
#pragma omp parallel for schedule(static) if (parallel)
    for (int h = 0; h < chunks; ++h) {
      double d[kWidth] = {};
      for (int i = h * kChunk; i < std::min(n, (h + 1) * kChunk); ++i) {
        double s[kWidth] = {};
        for (int e = outer[i]; e < outer[i + 1]; ++e) {
          const double a = values[e];
          const double* vj = &v[static_cast<size_t>(inner[e]) * kWidth];
          for (int c = 0; c < kWidth; ++c) s[c] += a * vj[c];
        }
        const double* vi = &v[static_cast<size_t>(i) * kWidth];
        for (int c = 0; c < kWidth; ++c) {
          out[static_cast<size_t>(i) * kWidth + c] = s[c];
          d[c] += vi[c] * s[c];
        }
      }
      if (dot)
        for (int c = 0; c < kWidth; ++c) {
          partial[(h * 2) * kWidth + c] = d[c];
          partial[(h * 2 + 1) * kWidth + c] = 0.0;
        }
    }
  };
  // Sums of per-chunk partials (2 kWidth per chunk) in chunk order.
  auto reduce = [&](double* first, double* second) {
    for (int c = 0; c < kWidth; ++c) first[c] = second[c] = 0.0;
    for (int h = 0; h < chunks; ++h)
      for (int c = 0; c < kWidth; ++c) {
        first[c] += partial[(h * 2) * kWidth + c];
        second[c] += partial[(h * 2 + 1) * kWidth + c];
      }
  };

  if (warm) {
    for (int i = 0; i < n; ++i)
      for (int c = 0; c < k; ++c) x[i * kWidth + c] = (*x0)(i, c);
    product(x, q, false);
    for (size_t e = 0; e < size; ++e) r[e] -= q[e];
  }
  double limit[kWidth] = {}, rz[kWidth], res2[kWidth];
  for (int c = 0; c < k; ++c) limit[c] = tolerance * b.col(c).norm();
  // p = D^-1 r; rz = r.D^-1 r; res2 = r.r
#pragma omp parallel for schedule(static) if (parallel)
  for (int h = 0; h < chunks; ++h) {
    double s1[kWidth] = {}, s2[kWidth] = {};
    for (int i = h * kChunk; i < std::min(n, (h + 1) * kChunk); ++i)
      for (int c = 0; c < kWidth; ++c) {
        const double ri = r[i * kWidth + c], zi = inv_diag[i] * ri;
        p[i * kWidth + c] = zi;
        s1[c] += ri * zi;
        s2[c] += ri * ri;
      }
    for (int c = 0; c < kWidth; ++c) {
      partial[(h * 2) * kWidth + c] = s1[c];
      partial[(h * 2 + 1) * kWidth + c] = s2[c];
    }
  }
  reduce(rz, res2);
  int it = 0;
  while (true) {
    double active[kWidth] = {};
    bool any = false;
    for (int c = 0; c < k; ++c)
      if (std::sqrt(res2[c]) > limit[c]) active[c] = 1.0, any = true;
    if (!any) break;
    if (it == max_iterations)
      throw Error("method S: the mass-matrix solve did not converge in " + std::to_string(max_iterations) +
                  " CG iterations");
    ++it;
    // q = M p and p.q
    double pq[kWidth], unused[kWidth];
    product(p, q, true);
    reduce(pq, unused);
    // Converged columns keep x and r (alpha = 0), as the reference does.
    double alpha[kWidth] = {};
    for (int c = 0; c < k; ++c) alpha[c] = active[c] != 0.0 ? rz[c] / pq[c] : 0.0;
    double rz_new[kWidth];
#pragma omp parallel for schedule(static) if (parallel)
    for (int h = 0; h < chunks; ++h) {
      double s1[kWidth] = {}, s2[kWidth] = {};
      for (int i = h * kChunk; i < std::min(n, (h + 1) * kChunk); ++i)
        for (int c = 0; c < kWidth; ++c) {
          const size_t e = static_cast<size_t>(i) * kWidth + c;
          x[e] += alpha[c] * p[e];
          r[e] -= alpha[c] * q[e];
          const double zi = inv_diag[i] * r[e];
          s1[c] += r[e] * zi;
          s2[c] += r[e] * r[e];
        }
      for (int c = 0; c < kWidth; ++c) {
        partial[(h * 2) * kWidth + c] = s1[c];
        partial[(h * 2 + 1) * kWidth + c] = s2[c];
      }
    }
    reduce(rz_new, res2);
    double beta[kWidth] = {};
    for (int c = 0; c < k; ++c) beta[c] = rz[c] > 0 ? rz_new[c] / rz[c] : 0.0;
#pragma omp parallel for schedule(static) if (parallel)
    for (int i = 0; i < n; ++i)
      for (int c = 0; c < kWidth; ++c) {
        const size_t e = static_cast<size_t>(i) * kWidth + c;
        p[e] = inv_diag[i] * r[e] + beta[c] * p[e];
      }
    for (int c = 0; c < k; ++c) rz[c] = rz_new[c];
  }
  if (iterations) *iterations = it;
  Eigen::MatrixXd out(n, k);
  for (int i = 0; i < n; ++i)
    for (int c = 0; c < k; ++c) out(i, c) = x[i * kWidth + c];
  return out;
}

}  // namespace

Eigen::MatrixXd solve_mass_cg_reference(const Eigen::SparseMatrix<double>& m, const Eigen::MatrixXd& b,
                                        double tolerance, int max_iterations, int* iterations,
                                        const Eigen::MatrixXd* x0, int parallel_rows) {
  const Eigen::Index n = b.rows(), k = b.cols();
  const Eigen::VectorXd inv_diag = m.diagonal().cwiseInverse();
  const bool warm = x0 && x0->rows() == n && x0->cols() == k;
  Eigen::MatrixXd x = warm ? *x0 : Eigen::MatrixXd::Zero(n, k), r = b;
  if (warm) {
    Eigen::MatrixXd mx(n, k);
    symmetric_product(m, x, mx, parallel_rows);
    r -= mx;
  }
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
  return x;
}

Eigen::MatrixXd solve_mass_cg(const Eigen::SparseMatrix<double>& m, const Eigen::MatrixXd& b, double tolerance,
                              int max_iterations, int* iterations, const Eigen::MatrixXd* x0,
                              int parallel_rows) {
  switch (b.cols()) {
    case 1: return solve_mass_cg_interleaved<1>(m, b, tolerance, max_iterations, iterations, x0, parallel_rows);
    case 2: return solve_mass_cg_interleaved<2>(m, b, tolerance, max_iterations, iterations, x0, parallel_rows);
    case 3: return solve_mass_cg_interleaved<3>(m, b, tolerance, max_iterations, iterations, x0, parallel_rows);
    case 4: return solve_mass_cg_interleaved<4>(m, b, tolerance, max_iterations, iterations, x0, parallel_rows);
    default: return solve_mass_cg_reference(m, b, tolerance, max_iterations, iterations, x0, parallel_rows);
  }
}

}  // namespace bendlab::loop_shell
