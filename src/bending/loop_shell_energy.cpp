#include "bendlab/bending/loop_shell_energy.hpp"

#include <algorithm>

namespace bendlab::loop_shell {

namespace {

// x, x_,v, x_,w, x_,vv, x_,vw, x_,ww at one point: rows of basis * P(idx).
using Derivs = Eigen::Matrix<double, 6, 3>;

Derivs derivatives(const PatchBasis& b, const Points& p, const int* idx) {
  Derivs d = Derivs::Zero();
  for (Eigen::Index i = 0; i < b.cols(); ++i) d.noalias() += b.col(i) * p.row(idx[i]);
  return d;
}

// Everything the energy gradient needs at one point.
struct Geometry {
  Vec3 a[2], dual[2], n;
  Vec3 xdd[3];         // x_,vv  x_,vw  x_,ww
  double g[2][2];      // inverse metric a^ab
  double bl[3];        // b_vv, b_vw, b_ww
  double J, H, K;
};

Geometry geometry(const Derivs& d) {
  Geometry s;
  s.a[0] = d.row(kDv).transpose();
  s.a[1] = d.row(kDw).transpose();
  for (int k = 0; k < 3; ++k) s.xdd[k] = d.row(kDvv + k).transpose();
  const Vec3 c = s.a[0].cross(s.a[1]);
  s.J = c.norm();
  s.n = c / s.J;
  const double g11 = s.a[0].dot(s.a[0]), g12 = s.a[0].dot(s.a[1]), g22 = s.a[1].dot(s.a[1]);
  const double det = g11 * g22 - g12 * g12;
  s.g[0][0] = g22 / det;
  s.g[0][1] = s.g[1][0] = -g12 / det;
  s.g[1][1] = g11 / det;
  for (int k = 0; k < 2; ++k) s.dual[k] = s.g[k][0] * s.a[0] + s.g[k][1] * s.a[1];
  for (int k = 0; k < 3; ++k) s.bl[k] = s.n.dot(s.xdd[k]);
  s.H = -0.5 * (s.g[0][0] * s.bl[0] + 2.0 * s.g[0][1] * s.bl[1] + s.g[1][1] * s.bl[2]);
  s.K = (s.bl[0] * s.bl[2] - s.bl[1] * s.bl[1]) / det;
  return s;
}

// Coefficients of N_I, N_I,v .. N_I,ww (rows) in w dE/dP_I at one point (row kValue is zero), with
// w = 2 kB w_q (see the header).
Derivs gradient_coefficients(const Geometry& s, double wq, const ShellTerms& terms, double wr) {
  // b^ab = a^ag b_gd a^db and m_b = b^ab a_a; c^g = a^ab Gamma^g_ab.
  const double bl[2][2] = {{s.bl[0], s.bl[1]}, {s.bl[1], s.bl[2]}};
  double bu[2][2] = {};
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j)
      for (int k = 0; k < 2; ++k)
        for (int l = 0; l < 2; ++l) bu[i][j] += s.g[i][k] * bl[k][l] * s.g[l][j];
  const Vec3 xab = s.g[0][0] * s.xdd[0] + 2.0 * s.g[0][1] * s.xdd[1] + s.g[1][1] * s.xdd[2];  // a^ab x_,ab
  const double c1 = s.dual[0].dot(xab), c2 = s.dual[1].dot(xab);
  double hj = wq * s.H * s.J, h2j = wq * s.H * s.H * s.J;
  if (!terms.plain) {  // c0 and ADE (ShellTerms); wr = w_q without 2 kB
    const double dh = s.H - terms.c0;
    hj = (wq * dh + 0.5 * terms.lambda * wr) * s.J;
    h2j = (wq * dh * dh + terms.lambda * wr * s.H) * s.J;
  }
  // Coefficients of N_I,v .. N_I,ww in dE/dP_I (see the header).
  Derivs qm;
  qm.row(kValue).setZero();
  for (int b = 0; b < 2; ++b) {
    const Vec3 mb = bu[0][b] * s.a[0] + bu[1][b] * s.a[1];
    const double cb = b == 0 ? c1 : c2;
    qm.row(kDv + b) = (2.0 * hj * mb + h2j * s.dual[b] + hj * cb * s.n).transpose();
  }
  qm.row(kDvv) = (-hj * s.g[0][0] * s.n).transpose();
  qm.row(kDvw) = (-hj * 2.0 * s.g[0][1] * s.n).transpose();
  qm.row(kDww) = (-hj * s.g[1][1] * s.n).transpose();
  return qm;
}

}  // namespace

QuadratureBases::QuadratureBases(TriangleRule rule, const std::vector<int>& valences) : rule_(std::move(rule)) {
  for (int n : valences) {
    if (n >= static_cast<int>(by_valence_.size())) by_valence_.resize(n + 1);
    if (!by_valence_[n].empty()) continue;
    for (int q = 0; q < rule_.size(); ++q) by_valence_[n].push_back(patch_basis(n, rule_.v[q], rule_.w[q]));
    if (n >= static_cast<int>(mass_products_.size())) mass_products_.resize(n + 1);
    const int m = n + 6;
    Eigen::MatrixXd& t = mass_products_[n];
    t.resize(m * (m + 1) / 2, rule_.size());
    for (int q = 0; q < rule_.size(); ++q) {
      const auto v = by_valence_[n][q].row(kValue);
      int k = 0;
      for (int a = 0; a < m; ++a)
        for (int b = a; b < m; ++b) t(k++, q) = v[a] * v[b];
    }
  }
}

const std::vector<PatchBasis>& QuadratureBases::at(int valence) const {
  if (valence < 0 || valence >= static_cast<int>(by_valence_.size()) || by_valence_[valence].empty())
    throw Error("method S: no quadrature basis for valence " + std::to_string(valence));
  return by_valence_[valence];
}

const Eigen::MatrixXd& QuadratureBases::mass_products(int valence) const {
  at(valence);  // validates
  return mass_products_[valence];
}

namespace {

// face_energy_fast for patches of M = N + 6 control points.
template <int M>
void face_fast(const QuadratureBases& bases, int valence, const Points& control, const int* idx, const ShellTerms& terms,
               bool with_h, FaceWork& work, double& energy) {
  using Basis = Eigen::Matrix<double, 6, M>;
  using Local = Eigen::Matrix<double, M, 3>;
  constexpr int kMaxRule = 16;
  const TriangleRule& rule = bases.rule();
  const std::vector<PatchBasis>& basis = bases.at(valence);
  const int nq = rule.size();
  Local p;
  for (int a = 0; a < M; ++a) p.row(a) = control.row(idx[a]);
  Local g = Local::Zero();
  Eigen::Matrix<double, M, 1> h = Eigen::Matrix<double, M, 1>::Zero();
  Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxRule, 1> wj(nq);
  for (int q = 0; q < nq; ++q) {
    const Eigen::Map<const Basis> b(basis[q].data());
    // Coefficient-based products (lazyProduct): these sizes are too small for Eigen's blocked
    // kernels, which it would pick from 20 rows + columns + depth on.
    const Derivs d = b.lazyProduct(p);
    const Geometry s = geometry(d);
    const double wq = 0.5 * rule.weight[q] * 2.0 * terms.kappa_b;  // 2 kB w_q
    energy += terms.plain ? wq * s.H * s.H * s.J : wq * (s.H - terms.c0) * (s.H - terms.c0) * s.J;
    wj[q] = 0.5 * rule.weight[q] * s.J;
    if (with_h) h.noalias() += (wj[q] * s.H) * b.row(kValue).transpose();
    const Derivs qm = gradient_coefficients(s, wq, terms, 0.5 * rule.weight[q]);
    g.noalias() += b.template bottomRows<5>().transpose().lazyProduct(qm.template bottomRows<5>());
  }
  work.m = M;
  for (int a = 0; a < M; ++a)
    for (int c = 0; c < 3; ++c) work.gradient[a][c] = g(a, c);
  constexpr int kSym = M * (M + 1) / 2;
  Eigen::Map<Eigen::Matrix<double, kSym, 1>>(work.mass).noalias() =
      Eigen::Map<const Eigen::Matrix<double, kSym, Eigen::Dynamic>>(bases.mass_products(valence).data(), kSym, nq)
          .lazyProduct(wj);
  if (with_h)
    for (int a = 0; a < M; ++a) work.h[a] = h[a];
}

}  // namespace

bool face_energy_fast(const QuadratureBases& bases, int valence, const Points& control, const int* idx,
                      const ShellTerms& terms, bool with_h, FaceWork& work, double& energy) {
  switch (valence) {
    case 3: face_fast<9>(bases, valence, control, idx, terms, with_h, work, energy); return true;
    case 4: face_fast<10>(bases, valence, control, idx, terms, with_h, work, energy); return true;
    case 5: face_fast<11>(bases, valence, control, idx, terms, with_h, work, energy); return true;
    case 6: face_fast<12>(bases, valence, control, idx, terms, with_h, work, energy); return true;
    case 7: face_fast<13>(bases, valence, control, idx, terms, with_h, work, energy); return true;
    case 8: face_fast<14>(bases, valence, control, idx, terms, with_h, work, energy); return true;
    default: return false;
  }
}

SurfacePoint surface_point(const PatchBasis& basis, const Points& control, const int* idx) {
  const Derivs d = derivatives(basis, control, idx);
  const Geometry g = geometry(d);
  SurfacePoint s;
  s.x = d.row(kValue).transpose();
  s.a1 = g.a[0];
  s.a2 = g.a[1];
  s.n = g.n;
  s.J = g.J;
  s.H = g.H;
  s.K = g.K;
  return s;
}

double face_energy(const std::vector<PatchBasis>& basis, const TriangleRule& rule, const Points& control,
                   const int* idx, const ShellTerms& terms, FaceLocal* local) {
  const int m = static_cast<int>(basis.front().cols());
  if (local) {
    local->gradient.setZero(m, 3);
    if (local->with_mass) local->mass.setZero(m, m);
    if (local->with_h) local->h.setZero(m);
  }
  double energy = 0.0;
  for (int q = 0; q < rule.size(); ++q) {
    const Geometry s = geometry(derivatives(basis[q], control, idx));
    const double wq = 0.5 * rule.weight[q] * 2.0 * terms.kappa_b;  // 2 kB w_q
    energy += terms.plain ? wq * s.H * s.H * s.J : wq * (s.H - terms.c0) * (s.H - terms.c0) * s.J;
    if (!local) continue;
    if (local->with_mass || local->with_h) {
      const double wj = 0.5 * rule.weight[q] * s.J;
      const auto n = basis[q].row(kValue);
      if (local->with_mass) local->mass.noalias() += (wj * n.transpose()) * n;
      if (local->with_h) local->h.noalias() += (wj * s.H) * n.transpose();
    }
    const Derivs qm = gradient_coefficients(s, wq, terms, 0.5 * rule.weight[q]);
    local->gradient.noalias() += basis[q].transpose() * qm;
  }
  return energy;
}

double shell_energy(const LoopPatches& patches, const QuadratureBases& bases, const Points& control,
                    const ShellTerms& terms, Points* gradient) {
  if (gradient) gradient->setZero(control.rows(), 3);
  double energy = 0.0;
  FaceLocal local;
  for (int f = 0; f < patches.num_faces(); ++f) {
    const int* idx = patches.face_points(f);
    energy += face_energy(bases.at(patches.valence[f]), bases.rule(), control, idx, terms,
                          gradient ? &local : nullptr);
    if (gradient)
      for (int i = 0; i < local.gradient.rows(); ++i) gradient->row(idx[i]) += local.gradient.row(i);
  }
  return energy;
}

double shell_mean_curvature_integral(const LoopPatches& patches, const QuadratureBases& bases, const Points& control) {
  const TriangleRule& rule = bases.rule();
  double m = 0.0;
  for (int f = 0; f < patches.num_faces(); ++f) {
    const auto& basis = bases.at(patches.valence[f]);
    for (int q = 0; q < rule.size(); ++q) {
      const SurfacePoint s = surface_point(basis[q], control, patches.face_points(f));
      m += 0.5 * rule.weight[q] * s.H * s.J;
    }
  }
  return m;
}

double shell_area(const LoopPatches& patches, const QuadratureBases& bases, const Points& control) {
  const TriangleRule& rule = bases.rule();
  double area = 0.0;
  for (int f = 0; f < patches.num_faces(); ++f) {
    const auto& basis = bases.at(patches.valence[f]);
    for (int q = 0; q < rule.size(); ++q)
      area += 0.5 * rule.weight[q] * surface_point(basis[q], control, patches.face_points(f)).J;
  }
  return area;
}

}  // namespace bendlab::loop_shell
