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

FaceColouring FaceColouring::build(const LoopPatches& patches, int num_points) {
  const int nf = patches.num_faces();
  std::vector<std::bitset<kMaxColours>> used(num_points);
  std::vector<int> colour(nf);
  int colours = 0;
  for (int f = 0; f < nf; ++f) {
    const int m = patches.valence[f] + 6;
    const int* idx = patches.face_points(f);
    std::bitset<kMaxColours> taken;
    for (int a = 0; a < m; ++a) taken |= used[idx[a]];
    int c = 0;
    while (c < kMaxColours && taken[c]) ++c;
    if (c == kMaxColours) throw Error("method S: more than 256 colours needed for the patches");
    colour[f] = c;
    colours = std::max(colours, c + 1);
    for (int a = 0; a < m; ++a) used[idx[a]].set(c);
  }
  FaceColouring out;
  out.offsets.assign(colours + 1, 0);
  for (int f = 0; f < nf; ++f) ++out.offsets[colour[f] + 1];
  for (int c = 0; c < colours; ++c) out.offsets[c + 1] += out.offsets[c];
  out.faces.resize(nf);
  std::vector<int> next(out.offsets.begin(), out.offsets.end() - 1);
  for (int f = 0; f < nf; ++f) out.faces[next[colour[f]]++] = f;
  return out;
}

double shell_energy_mass(const LoopPatches& patches, const QuadratureBases& bases, const MassPattern& mass,
                         const FaceColouring& colouring, const Points& control, double kappa_b, Points& gradient,
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
      // Faces of one colour touch disjoint control points: direct writes, no races. The implicit
      // barrier at the end of the loop separates the colours.
#pragma omp for schedule(static)
      for (int k = colouring.offsets[c]; k < colouring.offsets[c + 1]; ++k) {
        const int f = colouring.faces[k];
        const int* idx = patches.face_points(f);
        const int* slot = mass.face_slots(f);
        if (face_energy_fast(bases, patches.valence[f], control, idx, kappa_b, h_rhs != nullptr, work, energy)) {
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
        energy += face_energy(bases.at(patches.valence[f]), rule, control, idx, kappa_b, &local);
        const int n = static_cast<int>(local.gradient.rows());
        for (int a = 0; a < n; ++a) {
          gradient.row(idx[a]) += local.gradient.row(a);
          for (int b = 0; b < n; ++b) values[slot[a * n + b]] += local.mass(a, b);
          if (h_rhs) (*h_rhs)[idx[a]] += local.h[a];
        }
      }
    }
  }
  return energy;
}

}  // namespace bendlab::loop_shell
