#pragma once
// Method S (paper section 2.5): the Helfrich energy on the Loop subdivision limit surface and
// its force density from the weak form (Cirak et al.), derived in shared/spec/METHOD_S.md.
//
// Pipeline for nodes X:
//   1. control points P: L P = X (option control=solve, default), so every node is a limit
//      point and is compared where it sits; or P = X (control=nodes: the limit surface shrinks,
//      O(h^2)). L is the limit-mask matrix (loop_shell_limit.hpp).
//   2. (one pass over the quadrature points with step 3's M, over OpenMP threads by face
//      colours, loop_shell_assembly.hpp) E_B = 2 kB int H^2 dA on the limit surface (quadrature: option gauss = 1, 3, 6, 7, 12
//      points per triangle, default 6 = Dunavant degree 4; one rule for E, F and M), and the
//      generalised forces F_c = -dE_B/dP (exact gradient, loop_shell_energy.hpp).
//   3. force density coefficients f_c from M f_c = F_c, M_IJ = int N_I N_J dA: option
//      solver=cg (default; Jacobi-preconditioned CG to a relative residual of 1e-10,
//      loop_shell_solve.hpp, warm-started from the previous solution on the same topology) or solver=ldlt (sparse LDL^T whose symbolic analysis is kept per
//      topology; exact, but its fill-in makes it about 10x slower at 20480 triangles). Then f = sum_J N_J f_c,J is the density whose
//      weak form int f . dx dA = -dE_B; its sign is that of docs/conventions.md,
//      f = 2 kB (lapH + 2 H (H^2 - K)) n.
//   4. nodal values at the limit point of node i: f_i = sum_J L_iJ f_c,J, n_i from the tangent
//      masks, H_i and K_i from the limit surface at the node (option H=limit, default) or
//      H by L2 projection (H=projection: M h = int N_I H dA, H_i = (L h)_i).
//
// What BendingResult holds for S:
//   force_density  f_i above (force per area at the node's limit point);
//   area           Meyer's mixed area of the node mesh X (as for Methods C-E);
//   force          F_i = f_i * area_i, so that f = F / A_mixed as for every method. This is NOT
//                  -dE_B/dX: the exact generalised forces live on the control points
//                  (LoopShellState::control_force; they sum to zero and have zero torque
//                  exactly, and sum_I F_c,I = int f dA);
//   H, K, normal   as in step 4; lapH: NaN (Method S never forms Lap H, paper section 2.5);
//   energy         E_B.
// Default H=limit: it is the curvature of the very surface whose energy and forces are
// computed, and what the paper's table 2 shows for S (max error stagnating near the
// extraordinary vertices); H=projection is smoother (about 10x smaller average error).
//
// Meshes: closed, every triangle with at most one vertex of valence != 6 (refine the bare
// icosahedron once); otherwise bendlab::Error names the face.
#include <memory>
#include <mutex>
#include <unordered_map>

#include <Eigen/Sparse>

#include "bendlab/bending/bending_method.hpp"
#include "bendlab/bending/loop_shell_energy.hpp"
#include "bendlab/bending/method_registry.hpp"
#include "bendlab/bending/method_workspace.hpp"

namespace bendlab {

/// The intermediate quantities of Method S on one shape.
struct LoopShellState {
  Points control;             ///< control points P (N x 3)
  double energy = 0;          ///< E_B
  Points control_force;       ///< F_c = -dE_B/dP, generalised forces on the control points
  Points force_coefficients;  ///< f_c with M f_c = F_c
};

class LoopShellMethod final : public BendingMethod {
 public:
  enum class Control { Solve, Nodes };
  enum class HMode { Limit, Projection };
  enum class Solver { CG, LDLT };
  /// Relative residual of the CG solve of M f_c = F_c.
  static constexpr double kCgTolerance = 1e-10;

  /// Options: control = solve | nodes, gauss = 1 | 3 | 6 | 7 | 12, H = limit | projection,
  /// solver = cg | ldlt.
  /// Any other option or value is a bendlab::Error naming it.
  static std::unique_ptr<BendingMethod> create(const MethodOptions& options);
  /// The registry entry (method_registry.hpp): option schema and capabilities.
  static MethodInfo info();
  LoopShellMethod(Control control, int gauss_points, HMode h_mode, Solver solver = Solver::CG);
  ~LoopShellMethod() override;

  std::string name() const override { return "S"; }
  BendingResult compute(const Topology& topology, const Points& x, double kappa_b) const override;
  void compute_into(const Topology& topology, const Points& x, double kappa_b, BendingResult& out) const override;
  void forces(const Topology& topology, const Points& x, double kappa_b, Points& force) const override;
  std::optional<double> energy(const Topology& topology, const Points& x, double kappa_b) const override;

 protected:
  /// c0 and ADE on the limit surface (docs/conventions.md §5): E = 2 kB int (H - c0)^2 dA + E_ADE with
  /// M = int H dA, exact gradient on the control points (loop_shell_energy.hpp), f from the weak form.
  bool supports_membrane_terms() const override { return true; }
  BendingResult compute_terms(const Topology& topology, const Points& x, const BendingParameters& p) const override;
  void compute_terms_into(const Topology& topology, const Points& x, const BendingParameters& p,
                          BendingResult& out) const override;
  void forces_terms(const Topology& topology, const Points& x, const BendingParameters& p,
                    Points& force) const override;
  std::optional<double> energy_terms(const Topology& topology, const Points& x,
                                     const BendingParameters& p) const override;

 public:

  /// Control points for nodes x (step 1).
  Points control_points(const Topology& topology, const Points& x) const;
  /// Steps 1-3 (with c0 and ADE where `p` has them, docs/conventions.md §5).
  LoopShellState state(const Topology& topology, const Points& x, const BendingParameters& p) const;
  /// E_B of the limit surface of given control points, and dE_B/dP if gradient is not null; with
  /// c0 and ADE, E = 2 kB int (H - c0)^2 dA + E_ADE(int H dA) on the limit surface.
  double control_energy(const Topology& topology, const Points& control, const BendingParameters& p,
                        Points* gradient = nullptr) const;

  Control control() const { return control_; }
  int gauss_points() const { return gauss_points_; }
  HMode h_mode() const { return h_mode_; }
  Solver solver() const { return solver_; }

 private:
  struct Cache;
  struct Workspace;
  std::shared_ptr<Cache> cache_for(const Topology& topology) const;
  /// Steps 1-4 into r; with nodal_geometry the limit surface's n, H and K too (else NaN).
  void evaluate(const Topology& topology, const Points& x, const BendingParameters& p, bool nodal_geometry,
                BendingResult& r, Workspace& ws) const;
  /// The energy's coefficients for `p` at control points P (M = int H dA of the limit surface for ADE).
  loop_shell::ShellTerms shell_terms(Cache& cache, const Points& control, const BendingParameters& p,
                                     double* ade_energy) const;
  /// M X = B with the chosen solver.
  Eigen::MatrixXd solve_mass(Cache& cache, const Eigen::SparseMatrix<double>& m, const Eigen::MatrixXd& b) const;
  /// The same into ws's solution, with its buffers.
  void solve_mass(Cache& cache, const Eigen::SparseMatrix<double>& m, const Eigen::MatrixXd& b, Workspace& ws) const;

  Control control_;
  int gauss_points_;
  HMode h_mode_;
  Solver solver_;
  mutable std::mutex cache_mutex_;
  mutable std::unordered_map<const Topology*, std::shared_ptr<Cache>> cache_;
  /// The control points, gradient, mass matrix values, solves' buffers and forces()'s result of
  /// the last call, kept between calls (method_workspace.hpp).
  MethodWorkspace<Workspace> workspace_;
};

}  // namespace bendlab
