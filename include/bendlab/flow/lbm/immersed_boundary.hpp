#pragma once
// Immersed-boundary coupling of membrane nodes to the lattice (paper section 4.3.2, after Krueger;
// technical note shared/spec/LBM_IBM.md section 3). Node positions X are physical coordinates
// (box centred on the origin, Lattice::position); with dx = 1 a node force spread onto the lattice
// is a force density.
//   spread:       F(x) += sum_k F_k Phi(x - X_k)
//   interpolate:  U_k = sum_x u(x) Phi(x - X_k), u with the +F/2 correction (Lattice::velocity)
//   move:         X_k <- X_k + U_k dt (explicit Euler)
// Phi(r) = phi(r_x) phi(r_y) phi(r_z) with one of the 1-D kernels below; the support is periodic in
// x and y (and in z for a box without walls). With walls, a node whose support reaches past a
// wall is an error.
//
// One step in ESPResSo's order (ib_step): (1) the caller computes the membrane forces at X(t);
// (2) clear the lattice force and spread them; (3) collide with Guo forcing, stream, bounce back;
// (4) interpolate from the post-stream populations with +F/2 of the same force and move the nodes.
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "bendlab/core/types.hpp"
#include "bendlab/flow/lbm/lattice.hpp"

namespace bendlab::lbm {

enum class IbKernel {
  Phi2,  ///< linear hat 1 - |r| (|r| <= 1), 2 nodes per axis: ESPResSo's trilinear weights (default)
  Phi3,  ///< Roma-Peskin 3-point kernel (|r| <= 3/2)
  Phi4,  ///< Peskin 4-point cosine-free kernel (|r| <= 2)
};

/// phi(r), zero outside the support.
double ib_kernel(IbKernel kernel, double r);
/// Half-width of the support in dx: 1, 1.5, 2.
double ib_kernel_half_width(IbKernel kernel);

/// The lattice nodes and weights Phi(x - X) of one position (at most 4^3 nodes; nodes repeat if
/// the box is narrower than the support).
struct IbStencil {
  int size = 0;
  std::array<std::size_t, 64> node{};
  std::array<double, 64> weight{};
};
/// Throws bendlab::Error if X is not finite or its support crosses a wall.
IbStencil ib_stencil(const Lattice& lattice, const Vec3& X, IbKernel kernel);
/// The same for an n[0] x n[1] x n[2] lattice (with or without walls) that need not exist: node
/// indices i + n0 (j + n1 k), as Lattice::index (a subdomain maps them to its own nodes).
IbStencil ib_stencil(const std::array<int, 3>& n, bool walls, const Vec3& X, IbKernel kernel);
/// The same written to node[0 .. size) and weight[0 .. size), returning size ((2 ceil(half
/// width))^3): no stencil object to fill and copy for each position.
int ib_stencil_into(const std::array<int, 3>& n, bool walls, const Vec3& X, IbKernel kernel, std::size_t* node,
                    double* weight);

/// Adds sum_k F_k Phi(x - X_k) to the lattice force field (X, F: N x 3).
void spread_forces(Lattice& lattice, const Points& X, const Points& F, IbKernel kernel = IbKernel::Phi2);
/// U (resized to N x 3) = sum_x u(x) Phi(x - X_k), u = (sum f c + F/2) / rho.
void interpolate_velocity(const Lattice& lattice, const Points& X, Points& U, IbKernel kernel = IbKernel::Phi2);
/// The immersed boundary of many nodes whose stencils overlap (the vertices of many cells), for a
/// step in ESPResSo's order: prepare() takes the stencils of X once, spread() spreads the forces
/// through them, and after the lattice's step interpolate() reads the fluid velocity of every
/// lattice node in some stencil once (a membrane with about one vertex per dx visits each about
/// four times), in the order of the nodes' indices, so that the 19 population arrays are read
/// front to back, on OpenMP threads, and sums each node's stencil. Sums are taken in the same order
/// as spread_forces' and interpolate_velocity's, so the forces and U equal theirs bit for bit.
/// Keeps the stencils (16 bytes per entry, 8 entries per node with Phi2), a bit per lattice node
/// and a velocity per lattice node (24 bytes) between calls; not for concurrent use.
class IbInterpolator {
 public:
  /// The stencils of X, kept until the next prepare. Throws as ib_stencil (a non-finite position,
  /// a support across a wall), naming the node.
  void prepare(const Lattice& lattice, const Points& X, IbKernel kernel = IbKernel::Phi2);
  /// spread_forces through the prepared stencils; F has X's rows.
  void spread(Lattice& lattice, const Points& F) const;
  /// interpolate_velocity through the prepared stencils (after the lattice's step).
  void interpolate(const Lattice& lattice, Points& U);
  /// lattice.step(), then interpolate(lattice, U), bit for bit, with most of the gather done by
  /// the step while the populations it reads are in cache (Lattice::step_gathering).
  void step_and_interpolate(Lattice& lattice, Points& U);
  /// prepare(), then interpolate().
  void interpolate(const Lattice& lattice, const Points& X, Points& U, IbKernel kernel = IbKernel::Phi2);

 private:
  int per_node_ = 0;                   // stencil entries per node (zero weights kept)
  Eigen::Index nodes_ = 0;             // rows of the prepared X
  std::size_t lattice_nodes_ = 0;      // of the lattice the stencils index
  std::vector<std::size_t> node_;      // per_node_ entries per row of X
  std::vector<double> weight_;
  std::vector<std::uint64_t> marks_;   // a bit per lattice node: in some stencil
  std::vector<std::size_t> touched_;   // the marked nodes, ascending
  std::vector<double> velocity_;       // 3 per lattice node
  std::vector<Lattice::NodeRun> runs_;  // touched_ in runs of consecutive nodes of one x-row
  std::vector<std::uint8_t> gathered_;  // per run: its velocities computed by the step
  // touched_ and runs_ from the stencils (by prepare).
  void plan_runs(const Lattice& lattice);
  // The velocities of the runs not gathered yet (all when `gathered_` is empty).
  void gather_runs(const Lattice& lattice);
  // U from the stencils and the gathered velocities.
  void sum_stencils(Points& U) const;
};

/// X <- X + dt U.
void euler_move(Points& X, const Points& U, double dt = 1.0);

/// Steps (2)-(4) above for node forces F computed by the caller at the current X: clears the
/// lattice force, spreads F, advances the fluid one step, interpolates the node velocities into U
/// and moves X by U (dt = 1).
void ib_step(Lattice& lattice, Points& X, const Points& F, Points& U, IbKernel kernel = IbKernel::Phi2);

}  // namespace bendlab::lbm
