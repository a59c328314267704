#include "bendlab/bending/loop_shell_limit.hpp"

#include <cmath>
#include <map>
#include <numbers>
#include <vector>

#include "bendlab/bending/loop_shell_basis.hpp"
#include "bendlab/bending/loop_shell_energy.hpp"

namespace bendlab::loop_shell {

Eigen::SparseMatrix<double> limit_matrix(const Topology& t) {
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(t.ring_vertices().size() + t.num_vertices());
  for (int i = 0; i < t.num_vertices(); ++i) {
    const int n = t.valence(i);
    const double chi = limit_ring_weight(n);
    triplets.emplace_back(i, i, 1.0 - n * chi);
    for (int k = t.ring_begin(i); k < t.ring_end(i); ++k) triplets.emplace_back(i, t.ring_vertices()[k], chi);
  }
  Eigen::SparseMatrix<double> l(t.num_vertices(), t.num_vertices());
  l.setFromTriplets(triplets.begin(), triplets.end());
  return l;
}

LimitSolver::LimitSolver(const Topology& t) : inv_chi_(t.num_vertices()) {
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(t.ring_vertices().size() + t.num_vertices());
  for (int i = 0; i < t.num_vertices(); ++i) {
    const int n = t.valence(i);
    inv_chi_[i] = 1.0 / limit_ring_weight(n);
    triplets.emplace_back(i, i, inv_chi_[i] - n);
    for (int k = t.ring_begin(i); k < t.ring_end(i); ++k) triplets.emplace_back(i, t.ring_vertices()[k], 1.0);
  }
  Eigen::SparseMatrix<double> s(t.num_vertices(), t.num_vertices());
  s.setFromTriplets(triplets.begin(), triplets.end());
  ldlt_.compute(s);
  if (ldlt_.info() != Eigen::Success) throw Error("method S: the limit-mask matrix L is singular");
  inv_d_ = ldlt_.vectorD().cwiseInverse();  // 1 / d_i, as Eigen's solve forms it
}

Points LimitSolver::solve(const Points& x) const {
  const Eigen::MatrixXd p = ldlt_.solve(inv_chi_.asDiagonal() * Eigen::MatrixXd(x));
  return p;
}

void LimitSolver::solve(const Points& x, Points& p, Eigen::MatrixXd& rhs, Eigen::MatrixXd& work) const {
  // SimplicialCholeskyBase::_solve_impl step by step, with the same arithmetic (each product of
  // two numbers as there), the scalings and permutations written out: Eigen's temporaries would
  // allocate at every call.
  const Eigen::Index n = x.rows();
  rhs.resize(n, 3);
  for (Eigen::Index c = 0; c < 3; ++c)
    for (Eigen::Index i = 0; i < n; ++i) rhs(i, c) = inv_chi_[i] * x(i, c);
  work.resize(n, 3);
  const auto& perm = ldlt_.permutationP().indices();
  if (perm.size() > 0) {
    for (Eigen::Index i = 0; i < n; ++i) work.row(perm[i]) = rhs.row(i);  // P b
  } else {
    work = rhs;
  }
  const bool triangular = ldlt_.matrixL().nestedExpression().nonZeros() > 0;  // otherwise L = U = I
  if (triangular) ldlt_.matrixL().solveInPlace(work);
  if (inv_d_.size() > 0)
    for (Eigen::Index c = 0; c < 3; ++c)
      for (Eigen::Index i = 0; i < n; ++i) work(i, c) = inv_d_[i] * work(i, c);  // D^-1
  if (triangular) ldlt_.matrixU().solveInPlace(work);
  const auto& inv = ldlt_.permutationPinv().indices();
  if (inv.size() > 0) {
    for (Eigen::Index i = 0; i < n; ++i) rhs.row(inv[i]) = work.row(i);  // P^-1 x
  } else {
    rhs = work;
  }
  p = rhs;
}

Points limit_normals(const Topology& t, const Points& p) {
  Points normal;
  limit_normals(t, p, normal);
  return normal;
}

void limit_normals(const Topology& t, const Points& p, Points& normal) {
  normal.resize(t.num_vertices(), 3);
  for (int i = 0; i < t.num_vertices(); ++i) {
    const int n = t.valence(i);
    Vec3 t1 = Vec3::Zero(), t2 = Vec3::Zero();
    for (int j = 0; j < n; ++j) {
      const double phi = 2.0 * std::numbers::pi * j / n;
      const Vec3 pj = row(p, t.ring_vertices()[t.ring_begin(i) + j]);
      t1 += std::cos(phi) * pj;
      t2 += std::sin(phi) * pj;
    }
    normal.row(i) = t1.cross(t2).normalized().transpose();
  }
}

LimitCurvatureBases LimitCurvatureBases::build(const Topology& t, const LoopPatches& patches) {
  // The bases the loop of limit_curvatures reads, found by the same walk over the nodes.
  LimitCurvatureBases b;
  for (int i = 0; i < t.num_vertices(); ++i) {
    if (t.valence(i) == 6) {
      const int f = t.ring_faces()[t.ring_begin(i)];
      int c = 0;
      while (t.faces()(f, c) != i) ++c;
      const int local = (c - patches.corner[f] + 3) % 3;
      const int n = patches.valence[f];
      if (!b.corner.count({n, local}))
        b.corner.emplace(std::pair{n, local}, patch_basis(n, local == 1 ? 1.0 : 0.0, local == 2 ? 1.0 : 0.0));
      continue;
    }
    const int n = t.valence(i);
    if (!b.near_ev.count(n)) b.near_ev.emplace(n, patch_basis(n, kExtraordinarySample, kExtraordinarySample));
  }
  return b;
}

void limit_curvatures(const Topology& t, const LoopPatches& patches, const Points& p, Scalars& H, Scalars& K) {
  limit_curvatures(t, patches, LimitCurvatureBases::build(t, patches), p, H, K);
}

void limit_curvatures(const Topology& t, const LoopPatches& patches, const LimitCurvatureBases& bases,
                      const Points& p, Scalars& H, Scalars& K) {
  const int nv = t.num_vertices();
  H.resize(nv);
  K.resize(nv);
  for (int i = 0; i < nv; ++i) {
    const auto& ring_faces = t.ring_faces();
    if (t.valence(i) == 6) {
      // Any incident regular patch (one exists: at most one EV per face) at i's corner; an
      // incident irregular patch has i at its v = 1 or w = 1 corner, also well defined.
      const int f = ring_faces[t.ring_begin(i)];
      int c = 0;
      while (t.faces()(f, c) != i) ++c;
      const int local = (c - patches.corner[f] + 3) % 3;  // 0: u = 1, 1: v = 1, 2: w = 1
      const int n = patches.valence[f];
      const SurfacePoint s = surface_point(bases.corner.at({n, local}), p, patches.face_points(f));
      H[i] = s.H;
      K[i] = s.K;
      continue;
    }
    const int n = t.valence(i);
    const PatchBasis& near = bases.near_ev.at(n);
    double h = 0.0, k = 0.0;
    for (int r = t.ring_begin(i); r < t.ring_end(i); ++r) {
      const SurfacePoint s = surface_point(near, p, patches.face_points(ring_faces[r]));
      h += s.H;
      k += s.K;
    }
    H[i] = h / n;
    K[i] = k / n;
  }
}

}  // namespace bendlab::loop_shell
