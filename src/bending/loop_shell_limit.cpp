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
}

Points LimitSolver::solve(const Points& x) const {
  const Eigen::MatrixXd p = ldlt_.solve(inv_chi_.asDiagonal() * Eigen::MatrixXd(x));
  return p;
}

Points limit_normals(const Topology& t, const Points& p) {
  Points normal(t.num_vertices(), 3);
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
  return normal;
}

void limit_curvatures(const Topology& t, const LoopPatches& patches, const Points& p, Scalars& H, Scalars& K) {
  const int nv = t.num_vertices();
  H.resize(nv);
  K.resize(nv);
  // Bases at the three corners of a regular patch, and near the EV of an irregular one.
  const PatchBasis corners[3] = {patch_basis(6, 0.0, 0.0), patch_basis(6, 1.0, 0.0), patch_basis(6, 0.0, 1.0)};
  std::map<int, PatchBasis> near_ev;
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
      const SurfacePoint s =
          n == 6 ? surface_point(corners[local], p, patches.face_points(f))
                 : surface_point(patch_basis(n, local == 1 ? 1.0 : 0.0, local == 2 ? 1.0 : 0.0), p,
                                 patches.face_points(f));
      H[i] = s.H;
      K[i] = s.K;
      continue;
    }
    const int n = t.valence(i);
    auto it = near_ev.find(n);
    if (it == near_ev.end())
      it = near_ev.emplace(n, patch_basis(n, kExtraordinarySample, kExtraordinarySample)).first;
    double h = 0.0, k = 0.0;
    for (int r = t.ring_begin(i); r < t.ring_end(i); ++r) {
      const SurfacePoint s = surface_point(it->second, p, patches.face_points(ring_faces[r]));
      h += s.H;
      k += s.K;
    }
    H[i] = h / n;
    K[i] = k / n;
  }
}

}  // namespace bendlab::loop_shell
