#pragma once
// Method S (paper section 2.5): the consistent mass matrix of the limit surface,
// M_IJ = int N_I N_J dA = sum_T sum_q w_q J N_I N_J (METHOD_S.md section 4.1), and the
// L2-projection right-hand side int N_I g dA. M is symmetric positive definite with at most 37
// non-zeros per row (every pair of control points of one patch).
#include <vector>

#include <Eigen/Sparse>

#include "bendlab/bending/loop_shell_energy.hpp"
#include "bendlab/bending/loop_shell_patches.hpp"

namespace bendlab::loop_shell {

/// The sparsity pattern of M for one topology and, per face, where each (I, J) pair of its
/// patch lands in the value array, so that re-assembling M on new positions writes values only.
class MassPattern {
 public:
  explicit MassPattern(const LoopPatches& patches, int num_points);
  /// M with the pattern and zero values.
  const Eigen::SparseMatrix<double>& pattern() const { return pattern_; }
  /// Fills the values of m (which must have the pattern, e.g. a copy of pattern()) for control
  /// points P. If h_rhs is not null it receives int N_I H dA (for the L2 projection of H).
  void assemble(const LoopPatches& patches, const QuadratureBases& bases, const Points& control,
                Eigen::SparseMatrix<double>& m, Eigen::VectorXd* h_rhs = nullptr) const;
  /// Value indices of face f's (N+6)^2 pairs (I, J), row-major in the patch's local order.
  const int* face_slots(int f) const { return slots_.data() + slot_offsets_[f]; }

 private:
  Eigen::SparseMatrix<double> pattern_;
  std::vector<int> slot_offsets_, slots_;  // per face (N+6)^2 value indices, row-major (I, J)
};

}  // namespace bendlab::loop_shell
