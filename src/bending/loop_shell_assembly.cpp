#include "bendlab/bending/loop_shell_assembly.hpp"

#include <algorithm>
#include <bitset>

#include "bendlab/core/types.hpp"

namespace bendlab::loop_shell {

namespace {

// Colours a greedy colouring may use; a patch shares control points with a few dozen others
// (about 40 colours on the sphere meshes).
constexpr int kMaxColours = 256;

}  // namespace

FaceColouring FaceColouring::build(const LoopPatches& patches, int num_points, int block_size) {
  const int nf = patches.num_faces();
  const int nb = (nf + block_size - 1) / block_size;
  std::vector<std::bitset<kMaxColours>> used(num_points);
  std::vector<int> colour(nb);
  int colours = 0;
  for (int k = 0; k < nb; ++k) {
    const int first = k * block_size, last = std::min(nf, first + block_size);
    std::bitset<kMaxColours> taken;
    for (int f = first; f < last; ++f) {
      const int* idx = patches.face_points(f);
      for (int a = 0; a < patches.valence[f] + 6; ++a) taken |= used[idx[a]];
    }
    int c = 0;
    while (c < kMaxColours && taken[c]) ++c;
    if (c == kMaxColours) {
      if (block_size > 1) return build(patches, num_points, 1);
      throw Error("method S: more than 256 colours needed for the patches");
    }
    colour[k] = c;
    colours = std::max(colours, c + 1);
    for (int f = first; f < last; ++f) {
      const int* idx = patches.face_points(f);
      for (int a = 0; a < patches.valence[f] + 6; ++a) used[idx[a]].set(c);
    }
  }
  FaceColouring out;
  out.block_offsets.assign(colours + 1, 0);
  for (int k = 0; k < nb; ++k) ++out.block_offsets[colour[k] + 1];
  for (int c = 0; c < colours; ++c) out.block_offsets[c + 1] += out.block_offsets[c];
  std::vector<int> order(nb);
  std::vector<int> next(out.block_offsets.begin(), out.block_offsets.end() - 1);
  for (int k = 0; k < nb; ++k) order[next[colour[k]]++] = k;
  out.offsets.assign(colours + 1, 0);
  out.faces.reserve(nf);
  out.blocks.reserve(nb + 1);
  for (int c = 0; c < colours; ++c) {
    for (int j = out.block_offsets[c]; j < out.block_offsets[c + 1]; ++j) {
      out.blocks.push_back(static_cast<int>(out.faces.size()));
      const int first = order[j] * block_size, last = std::min(nf, first + block_size);
      for (int f = first; f < last; ++f) out.faces.push_back(f);
    }
    out.offsets[c + 1] = static_cast<int>(out.faces.size());
  }
  out.blocks.push_back(nf);
  return out;
}

double shell_energy_mass(const LoopPatches& patches, const QuadratureBases& bases, const MassPattern& mass,
                         const FaceColouring& colouring, const Points& control, const ShellTerms& terms, Points& gradient,
                         Eigen::SparseMatrix<double>& m, Eigen::VectorXd* h_rhs, int parallel_faces) {
  gradient.setZero(control.rows(), 3);
  double* values = m.valuePtr();
  std::fill(values, values + m.nonZeros(), 0.0);
  if (h_rhs) h_rhs->setZero(control.rows());
  const TriangleRule& rule = bases.rule();
  double energy = 0.0;
#pragma omp parallel reduction(+ : energy) if (patches.num_faces() >= parallel_faces)
  {
    FaceWork work;
    FaceLocal local;  // the reference kernel, for valences without a fixed-size one
    local.with_mass = true;
    local.with_h = h_rhs != nullptr;
    for (int c = 0; c < colouring.num_colours(); ++c) {
      // Blocks of one colour touch disjoint control points: direct writes, no races; the faces of
      // a block run in order on one thread. The implicit barrier at the end of the loop separates
      // the colours.
#pragma omp for schedule(static)
      for (int j = colouring.block_offsets[c]; j < colouring.block_offsets[c + 1]; ++j) {
        for (int k = colouring.blocks[j]; k < colouring.blocks[j + 1]; ++k) {
        const int f = colouring.faces[k];
        const int* idx = patches.face_points(f);
        const int* slot = mass.face_slots(f);
        if (face_energy_fast(bases, patches.valence[f], control, idx, terms, h_rhs != nullptr, work, energy)) {
          const int n = work.m;
          const double* upper = work.mass;
          for (int a = 0; a < n; ++a) {
            for (int d = 0; d < 3; ++d) gradient(idx[a], d) += work.gradient[a][d];
            values[slot[a * n + a]] += *upper++;
            for (int b = a + 1; b < n; ++b, ++upper) {
              values[slot[a * n + b]] += *upper;
              values[slot[b * n + a]] += *upper;
            }
            if (h_rhs) (*h_rhs)[idx[a]] += work.h[a];
          }
          continue;
        }
        energy += face_energy(bases.at(patches.valence[f]), rule, control, idx, terms, &local);
        const int n = static_cast<int>(local.gradient.rows());
        for (int a = 0; a < n; ++a) {
          gradient.row(idx[a]) += local.gradient.row(a);
          for (int b = 0; b < n; ++b) values[slot[a * n + b]] += local.mass(a, b);
          if (h_rhs) (*h_rhs)[idx[a]] += local.h[a];
        }
        }
      }
    }
  }
  return energy;
}

}  // namespace bendlab::loop_shell
