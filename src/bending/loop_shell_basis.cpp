#include "bendlab/bending/loop_shell_basis.hpp"

#include <array>
#include <cmath>
#include <map>
#include <mutex>
#include <numbers>
#include <string>

#include "bendlab/core/types.hpp"

namespace bendlab::loop_shell {

namespace {

// One term c u^i v^j w^k of 12 N_k (METHOD_S.md section 1).
struct Term {
  int c, i, j, k;
};

// 12 N_k for Cirak's nodes 1..12, as monomials in (u, v, w).
const std::array<std::vector<Term>, 12>& box_spline_terms() {
  static const std::array<std::vector<Term>, 12> terms = {{
      {{1, 4, 0, 0}, {2, 3, 1, 0}},
      {{1, 4, 0, 0}, {2, 3, 0, 1}},
      {{1, 4, 0, 0}, {2, 3, 0, 1}, {6, 3, 1, 0}, {6, 2, 1, 1}, {12, 2, 2, 0}, {6, 1, 2, 1}, {6, 1, 3, 0},
       {2, 0, 3, 1}, {1, 0, 4, 0}},
      {{6, 4, 0, 0}, {24, 3, 0, 1}, {24, 2, 0, 2}, {8, 1, 0, 3}, {1, 0, 0, 4}, {24, 3, 1, 0}, {60, 2, 1, 1},
       {36, 1, 1, 2}, {6, 0, 1, 3}, {24, 2, 2, 0}, {36, 1, 2, 1}, {12, 0, 2, 2}, {8, 1, 3, 0}, {6, 0, 3, 1},
       {1, 0, 4, 0}},
      {{1, 4, 0, 0}, {6, 3, 0, 1}, {12, 2, 0, 2}, {6, 1, 0, 3}, {1, 0, 0, 4}, {2, 3, 1, 0}, {6, 2, 1, 1},
       {6, 1, 1, 2}, {2, 0, 1, 3}},
      {{2, 1, 3, 0}, {1, 0, 4, 0}},
      {{1, 4, 0, 0}, {6, 3, 0, 1}, {12, 2, 0, 2}, {6, 1, 0, 3}, {1, 0, 0, 4}, {8, 3, 1, 0}, {36, 2, 1, 1},
       {36, 1, 1, 2}, {8, 0, 1, 3}, {24, 2, 2, 0}, {60, 1, 2, 1}, {24, 0, 2, 2}, {24, 1, 3, 0}, {24, 0, 3, 1},
       {6, 0, 4, 0}},
      {{1, 4, 0, 0}, {8, 3, 0, 1}, {24, 2, 0, 2}, {24, 1, 0, 3}, {6, 0, 0, 4}, {6, 3, 1, 0}, {36, 2, 1, 1},
       {60, 1, 1, 2}, {24, 0, 1, 3}, {12, 2, 2, 0}, {36, 1, 2, 1}, {24, 0, 2, 2}, {6, 1, 3, 0}, {8, 0, 3, 1},
       {1, 0, 4, 0}},
      {{2, 1, 0, 3}, {1, 0, 0, 4}},
      {{2, 0, 3, 1}, {1, 0, 4, 0}},
      {{2, 1, 0, 3}, {1, 0, 0, 4}, {6, 1, 1, 2}, {6, 0, 1, 3}, {6, 1, 2, 1}, {12, 0, 2, 2}, {2, 1, 3, 0},
       {6, 0, 3, 1}, {1, 0, 4, 0}},
      {{1, 0, 0, 4}, {2, 0, 1, 3}},
  }};
  return terms;
}

// d^d/dx^d x^p.
inline double dpow(double x, int p, int d) {
  if (d > p) return 0.0;
  double c = 1.0;
  for (int m = 0; m < d; ++m) c *= p - m;
  return c * std::pow(x, p - d);
}

// Row r of the 6 x (N+12) selection "Pick" for the three sub-triangles (METHOD_S.md section 2):
// the new local index that becomes Cirak node r + 1 of the regular sub-patch.
std::array<int, 12> pick(int sub, int n) {
  if (sub == 0) return {2, 0, n + 3, 1, n, n + 8, n + 2, n + 1, n + 4, n + 7, n + 6, n + 9};
  if (sub == 1) return {0, n - 1, 1, n, n + 5, n + 2, n + 1, n + 4, n + 11, n + 6, n + 9, n + 10};
  return {n + 9, n + 6, n + 4, n + 1, n + 2, n + 5, n, 1, n + 3, n - 1, 0, 2};
}

// A-bar per valence, built once (thread-safe).
const Eigen::MatrixXd& cached_subdivision_matrix(int n) {
  static std::mutex mutex;
  static std::map<int, Eigen::MatrixXd> cache;
  std::lock_guard<std::mutex> lock(mutex);
  auto it = cache.find(n);
  if (it == cache.end()) it = cache.emplace(n, subdivision_matrix(n)).first;
  return it->second;
}

}  // namespace

double loop_beta(int valence) {
  const double c = 3.0 / 8.0 + std::cos(2.0 * std::numbers::pi / valence) / 4.0;
  return (5.0 / 8.0 - c * c) / valence;
}

double limit_ring_weight(int valence) { return 1.0 / (valence + 3.0 / (8.0 * loop_beta(valence))); }

Eigen::Matrix<double, 6, 12> box_splines(double v, double w) {
  const double u = 1.0 - v - w;
  Eigen::Matrix<double, 6, 12> b = Eigen::Matrix<double, 6, 12>::Zero();
  const auto& terms = box_spline_terms();
  for (int k = 0; k < 12; ++k) {
    for (const Term& t : terms[k]) {
      // Partials in (u, v, w), then d/dv = dv - du, d/dw = dw - du (u = 1 - v - w).
      auto p = [&](int du, int dv, int dw) { return t.c * dpow(u, t.i, du) * dpow(v, t.j, dv) * dpow(w, t.k, dw); };
      b(kValue, k) += p(0, 0, 0);
      b(kDv, k) += p(0, 1, 0) - p(1, 0, 0);
      b(kDw, k) += p(0, 0, 1) - p(1, 0, 0);
      b(kDvv, k) += p(0, 2, 0) - 2.0 * p(1, 1, 0) + p(2, 0, 0);
      b(kDvw, k) += p(0, 1, 1) - p(1, 1, 0) - p(1, 0, 1) + p(2, 0, 0);
      b(kDww, k) += p(0, 0, 2) - 2.0 * p(1, 0, 1) + p(2, 0, 0);
    }
  }
  return b / 12.0;
}

const std::vector<std::pair<int, int>>& box_spline_offsets() {
  static const std::vector<std::pair<int, int>> offsets = {{0, -1}, {-1, 0}, {1, -1}, {0, 0}, {-1, 1}, {2, -1},
                                                           {1, 0},  {0, 1},  {-1, 2}, {2, 0}, {1, 1},  {0, 2}};
  return offsets;
}

const std::vector<int>& regular_local_to_cirak() {
  static const std::vector<int> map = {3, 6, 2, 0, 1, 4, 7, 10, 9, 5, 11, 8};
  return map;
}

Eigen::MatrixXd subdivision_matrix(int n) {
  if (n < 3) throw Error("method S: vertex valence " + std::to_string(n) + " is below 3");
  const double beta = loop_beta(n);
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(n + 12, n + 6);
  auto edge = [&](int row, int p, int q, int r, int s) {  // 3/8 (p + q) + 1/8 (r + s)
    a(row, p) += 3.0 / 8.0;
    a(row, q) += 3.0 / 8.0;
    a(row, r) += 1.0 / 8.0;
    a(row, s) += 1.0 / 8.0;
  };
  a(0, 0) = 1.0 - n * beta;
  for (int i = 1; i <= n; ++i) {
    a(0, i) = beta;
    const int prev = i == 1 ? n : i - 1, next = i == n ? 1 : i + 1;
    edge(i, 0, i, prev, next);
  }
  edge(n + 1, 1, n, 0, n + 1);
  edge(n + 3, 1, 2, 0, n + 3);
  edge(n + 5, n - 1, n, 0, n + 5);
  // Regular (valence 6) old vertices A and B.
  a(n + 2, 1) += 5.0 / 8.0;
  for (int k : {0, 2, n, n + 1, n + 2, n + 3}) a(n + 2, k) += 1.0 / 16.0;
  a(n + 4, n) += 5.0 / 8.0;
  for (int k : {0, 1, n - 1, n + 1, n + 4, n + 5}) a(n + 4, k) += 1.0 / 16.0;
  edge(n + 6, 1, n + 1, n, n + 2);
  edge(n + 7, 1, n + 2, n + 1, n + 3);
  edge(n + 8, 1, n + 3, 2, n + 2);
  edge(n + 9, n, n + 1, 1, n + 4);
  edge(n + 10, n, n + 4, n + 1, n + 5);
  edge(n + 11, n, n + 5, n - 1, n + 4);
  return a;
}

PatchBasis patch_basis(int n, double v, double w) {
  constexpr double tol = 1e-12;
  if (!(v >= -tol && w >= -tol && v + w <= 1.0 + tol))
    throw Error("method S: patch parameter (" + std::to_string(v) + ", " + std::to_string(w) +
                ") lies outside the reference triangle");
  if (n == 6) {
    const Eigen::Matrix<double, 6, 12> b = box_splines(v, w);
    PatchBasis out(6, 12);
    const auto& map = regular_local_to_cirak();
    for (int i = 0; i < 12; ++i) out.col(i) = b.col(map[i]);
    return out;
  }
  return patch_basis_by_subdivision(n, v, w);
}

PatchBasis patch_basis_by_subdivision(int n, double v, double w) {
  if (n < 3) throw Error("method S: vertex valence " + std::to_string(n) + " is below 3");
  if (v + w <= 0.0)
    throw Error("method S: the patch of an extraordinary vertex has no parametric derivatives at the vertex "
                "itself; use the limit masks there");
  // Smallest level with 2^level (v + w) >= 1/2: the point lies in one of the three outer
  // sub-triangles of the level-th subdivided patch (METHOD_S.md section 2).
  int level = 0;
  double sv = v, sw = w;
  while (sv + sw < 0.5) {
    sv *= 2.0;
    sw *= 2.0;
    ++level;
  }
  int sub;
  double vp, wp, sign;
  if (sv >= 0.5) {
    sub = 0, vp = 2.0 * sv - 1.0, wp = 2.0 * sw, sign = 1.0;
  } else if (sw >= 0.5) {
    sub = 1, vp = 2.0 * sv, wp = 2.0 * sw - 1.0, sign = 1.0;
  } else {
    sub = 2, vp = 1.0 - 2.0 * sv, wp = 1.0 - 2.0 * sw, sign = -1.0;
  }
  const Eigen::Matrix<double, 6, 12> b = box_splines(vp, wp);
  const std::array<int, 12> p = pick(sub, n);
  const Eigen::MatrixXd& abar = cached_subdivision_matrix(n);
  // b Pick A-bar A^level, applied from the left.
  Eigen::MatrixXd row = Eigen::MatrixXd::Zero(6, n + 6);
  for (int c = 0; c < 12; ++c) row += b.col(c) * abar.row(p[c]);
  const auto a = abar.topRows(n + 6);
  for (int k = 0; k < level; ++k) row = (row * a).eval();
  const double d1 = sign * std::ldexp(1.0, level + 1), d2 = std::ldexp(1.0, 2 * (level + 1));
  row.middleRows(kDv, 2) *= d1;
  row.bottomRows(3) *= d2;
  return row;
}

TriangleRule dunavant_rule(int points) {
  TriangleRule r;
  auto centroid = [&](double wt) {
    r.v.push_back(1.0 / 3.0);
    r.w.push_back(1.0 / 3.0);
    r.weight.push_back(wt);
  };
  auto orbit3 = [&](double a, double wt) {  // barycentrics (1 - 2a, a, a) and permutations
    const double b = 1.0 - 2.0 * a;
    const double vs[3] = {a, b, a}, ws[3] = {a, a, b};
    for (int k = 0; k < 3; ++k) {
      r.v.push_back(vs[k]);
      r.w.push_back(ws[k]);
      r.weight.push_back(wt);
    }
  };
  auto orbit6 = [&](double a, double b, double wt) {  // (a, b, 1 - a - b) and permutations
    const double c = 1.0 - a - b;
    const double t[6][2] = {{a, b}, {b, a}, {a, c}, {c, a}, {b, c}, {c, b}};
    for (const auto& p : t) {
      r.v.push_back(p[0]);
      r.w.push_back(p[1]);
      r.weight.push_back(wt);
    }
  };
  switch (points) {
    case 1: centroid(1.0); break;
    case 3: orbit3(1.0 / 6.0, 1.0 / 3.0); break;
    case 6:
      orbit3(0.445948490915965, 0.223381589678011);
      orbit3(0.091576213509771, 0.109951743655322);
      break;
    case 7:
      centroid(0.225);
      orbit3(0.470142064105115, 0.132394152788506);
      orbit3(0.101286507323456, 0.125939180544827);
      break;
    case 12:
      orbit3(0.063089014491502, 0.050844906370207);
      orbit3(0.249286745170910, 0.116786275726379);
      orbit6(0.310352451033785, 0.053145049844816, 0.082851075618374);
      break;
    default:
      throw Error("method S: no symmetric triangle rule with " + std::to_string(points) +
                  " points (known: 1, 3, 6, 7, 12)");
  }
  return r;
}

}  // namespace bendlab::loop_shell
