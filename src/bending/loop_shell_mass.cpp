#include "bendlab/bending/loop_shell_mass.hpp"

#include <algorithm>

namespace bendlab::loop_shell {

MassPattern::MassPattern(const LoopPatches& patches, int num_points) {
  std::vector<Eigen::Triplet<double>> triplets;
  for (int f = 0; f < patches.num_faces(); ++f) {
    const int m = patches.valence[f] + 6;
    const int* idx = patches.face_points(f);
    for (int a = 0; a < m; ++a)
      for (int b = 0; b < m; ++b) triplets.emplace_back(idx[a], idx[b], 0.0);
  }
  pattern_.resize(num_points, num_points);
  pattern_.setFromTriplets(triplets.begin(), triplets.end());
  pattern_.makeCompressed();
  slot_offsets_.push_back(0);
  const int* outer = pattern_.outerIndexPtr();
  const int* inner = pattern_.innerIndexPtr();
  for (int f = 0; f < patches.num_faces(); ++f) {
    const int m = patches.valence[f] + 6;
    const int* idx = patches.face_points(f);
    for (int a = 0; a < m; ++a)
      for (int b = 0; b < m; ++b) {
        // Column-major: column idx[b], row idx[a].
        const int* first = inner + outer[idx[b]];
        const int* last = inner + outer[idx[b] + 1];
        slots_.push_back(static_cast<int>(std::lower_bound(first, last, idx[a]) - inner));
      }
    slot_offsets_.push_back(static_cast<int>(slots_.size()));
  }
}

void MassPattern::assemble(const LoopPatches& patches, const QuadratureBases& bases, const Points& control,
                           Eigen::SparseMatrix<double>& mat, Eigen::VectorXd* h_rhs) const {
  double* values = mat.valuePtr();
  std::fill(values, values + mat.nonZeros(), 0.0);
  if (h_rhs) h_rhs->setZero(control.rows());
  const TriangleRule& rule = bases.rule();
  Eigen::MatrixXd local;
  for (int f = 0; f < patches.num_faces(); ++f) {
    const int m = patches.valence[f] + 6;
    const int* idx = patches.face_points(f);
    const auto& basis = bases.at(patches.valence[f]);
    local.setZero(m, m);
    for (int q = 0; q < rule.size(); ++q) {
      const SurfacePoint s = surface_point(basis[q], control, idx);
      const double wj = 0.5 * rule.weight[q] * s.J;
      const auto n = basis[q].row(kValue);
      local.noalias() += (wj * n.transpose()) * n;
      if (h_rhs)
        for (int a = 0; a < m; ++a) (*h_rhs)[idx[a]] += wj * s.H * n[a];
    }
    const int* slot = slots_.data() + slot_offsets_[f];
    for (int a = 0; a < m; ++a)
      for (int b = 0; b < m; ++b) values[slot[a * m + b]] += local(a, b);
  }
}

}  // namespace bendlab::loop_shell
