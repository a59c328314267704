#pragma once
// Method S (paper section 2.5): one pass over the quadrature points that yields everything an
// evaluation needs from the control points P: E_B, dE_B/dP (loop_shell_energy.hpp), the values of
// the consistent mass matrix M (loop_shell_mass.hpp) and optionally int N_I H dA. Each patch goes
// through face_energy_fast (fixed-size products, tabulated N_a N_b; loop_shell_energy.hpp), or
// face_energy for a valence above FaceWork::kMaxFastValence. The serial functions shell_energy()
// and MassPattern::assemble() stay the reference (tested equal).
//
// Parallel without conflicts: the faces are coloured so that no two faces of one colour share a
// control point (FaceColouring); the faces of one colour are evaluated by all OpenMP threads and
// each writes its patch's entries of the gradient and of M directly. Every entry therefore
// receives its contributions in the same order (colour by colour) whatever the thread count, so
// the gradient, M and int N_I H dA do not depend on it (bit for bit); E_B is a reduction over
// the threads (equal to round-off).
#include <vector>

#include <Eigen/Sparse>

#include "bendlab/bending/loop_shell_energy.hpp"
#include "bendlab/bending/loop_shell_mass.hpp"
#include "bendlab/bending/loop_shell_patches.hpp"

namespace bendlab::loop_shell {

/// Greedy colouring of blocks of consecutive faces: blocks of one colour have disjoint sets of
/// control points. Blocks keep the sweep local in memory (a colour of single faces spreads over
/// the whole mesh, and each of its ~40 sweeps touches all of the gradient and of M); the
/// subdivision meshes number the faces of a region consecutively, so blocks are compact.
struct FaceColouring {
  /// Faces of colour c: faces[offsets[c] .. offsets[c+1]), ascending.
  std::vector<int> offsets, faces;
  /// Blocks of colour c: block_offsets[c] .. block_offsets[c+1]); block k holds
  /// faces[blocks[k] .. blocks[k+1]) (blocks ends with faces.size()).
  std::vector<int> block_offsets, blocks;
  int num_colours() const { return static_cast<int>(offsets.size()) - 1; }
  /// block_size consecutive faces per block (1: faces coloured one by one). If blocks would need
  /// more colours than the colouring holds, falls back to single faces.
  static FaceColouring build(const LoopPatches& patches, int num_points, int block_size = 32);
};

/// Meshes with fewer faces run on one thread: each colour ends with a barrier (about 40 per
/// pass), which costs more than it saves on small meshes, and far more on a loaded machine.
constexpr int kParallelFaces = 4096;

/// E_B, and into `gradient` (resized to P's shape) dE_B/dP, into m's values (m must have
/// mass.pattern()'s pattern) M for P, and into h_rhs (if not null) int N_I H dA. OpenMP threads
/// from `parallel_faces` faces on.
double shell_energy_mass(const LoopPatches& patches, const QuadratureBases& bases, const MassPattern& mass,
                         const FaceColouring& colouring, const Points& control, const ShellTerms& terms, Points& gradient,
                         Eigen::SparseMatrix<double>& m, Eigen::VectorXd* h_rhs = nullptr,
                         int parallel_faces = kParallelFaces);

}  // namespace bendlab::loop_shell
