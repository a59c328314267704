#include "bendlab/bending/loop_shell.hpp"

#include <Eigen/SparseCholesky>
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <set>

#include "bendlab/bending/loop_shell_assembly.hpp"
#include "bendlab/bending/loop_shell_energy.hpp"
#include "bendlab/bending/loop_shell_limit.hpp"
#include "bendlab/bending/loop_shell_mass.hpp"
#include "bendlab/bending/loop_shell_patches.hpp"
#include "bendlab/bending/loop_shell_solve.hpp"
#include "bendlab/bending/method_registry.hpp"
#include "bendlab/geometry/mesh_geometry.hpp"

namespace bendlab {

using SparseMatrix = Eigen::SparseMatrix<double>;

namespace {

std::vector<int> distinct(const std::vector<int>& values) {
  const std::set<int> s(values.begin(), values.end());
  return {s.begin(), s.end()};
}

}  // namespace

// Everything that depends on the connectivity only. The factorisations are used under `mutex`.
struct LoopShellMethod::Cache {
  Cache(const Topology& t, int gauss_points, bool solve_control, bool factorize_mass)
      : num_vertices(t.num_vertices()),
        faces(t.faces()),
        patches(loop_shell::LoopPatches::build(t)),
        bases(loop_shell::dunavant_rule(gauss_points), distinct(patches.valence)),
        limit(loop_shell::limit_matrix(t)),
        mass(patches, t.num_vertices()),
        colouring(loop_shell::FaceColouring::build(patches, t.num_vertices())),
        curvature_bases(loop_shell::LimitCurvatureBases::build(t, patches)) {
    if (solve_control) limit_solver.emplace(t);
    if (factorize_mass) mass_ldlt.analyzePattern(mass.pattern());
  }
  bool matches(const Topology& t) const { return t.num_vertices() == num_vertices && t.faces() == faces; }

  int num_vertices;
  Faces faces;
  loop_shell::LoopPatches patches;
  loop_shell::QuadratureBases bases;
  SparseMatrix limit;
  loop_shell::MassPattern mass;
  loop_shell::FaceColouring colouring;
  loop_shell::LimitCurvatureBases curvature_bases;
  std::mutex mutex;
  // The last solution of M f_c = F_c (under `mutex`): the next CG solve on this topology starts
  // from it. Successive shapes of a flow run differ little, so this saves most iterations; the
  // result still meets the same residual tolerance.
  Eigen::MatrixXd last_solution;
  std::optional<loop_shell::LimitSolver> limit_solver;
  Eigen::SimplicialLDLT<SparseMatrix> mass_ldlt;
};

namespace {

// Topologies whose caches are kept at once (a flow solver and a study use one or a few).
constexpr size_t kMaxCachedTopologies = 8;

}  // namespace

// What one evaluation writes, kept by the method instance and reused from call to call
// (method_workspace.hpp); m and its pattern belong to `cache`.
struct LoopShellMethod::Workspace {
  std::shared_ptr<Cache> cache;
  SparseMatrix m;
  Points control, gradient;
  Eigen::MatrixXd limit_rhs, limit_work;
  Eigen::VectorXd h_rhs;
  Eigen::MatrixXd rhs, start, solution, fc, product;
  Eigen::VectorXd h_product;
  loop_shell::CgBuffers cg;
  CornerValues corner_mixed;
  BendingResult result;  // forces()
};

std::unique_ptr<BendingMethod> LoopShellMethod::create(const MethodOptions& options) {
  const MethodOptions o = resolve_method_options(info(), options);
  const Control control = o.at("control") == "nodes" ? Control::Nodes : Control::Solve;
  const int gauss = std::stoi(o.at("gauss"));
  const HMode h = o.at("H") == "projection" ? HMode::Projection : HMode::Limit;
  const Solver solver = o.at("solver") == "ldlt" ? Solver::LDLT : Solver::CG;
  return std::make_unique<LoopShellMethod>(control, gauss, h, solver);
}

MethodInfo LoopShellMethod::info() {
  MethodInfo m{"S",
               "Loop subdivision thin shell: Helfrich energy on the limit surface, f from the weak form "
               "(section 2.5)",
               {choice_option("control", {"solve", "nodes"}, "solve",
                              "control points: solve L P = X (nodes are limit points) or P = X"),
                choice_option("gauss", {"1", "3", "6", "7", "12"}, "6", "quadrature points per triangle"),
                choice_option("H", {"limit", "projection"}, "limit",
                              "nodal H: the limit surface's own, or its L2 projection"),
                choice_option("solver", {"cg", "ldlt"}, "cg", "mass-matrix solve M f_c = F_c")},
               {},
               &LoopShellMethod::create};
  m.capabilities.has_energy = true;
  m.capabilities.defines_lapH = false;
  // At most one extraordinary vertex per triangle (the bare icosahedron and Rivara meshes are refused).
  m.capabilities.needs_admissible_mesh = true;
  m.capabilities.cost = "O(N) per patch + two sparse solves (L P = X, M f_c = F_c)";
  return m;
}

LoopShellMethod::LoopShellMethod(Control control, int gauss_points, HMode h_mode, Solver solver)
    : control_(control), gauss_points_(gauss_points), h_mode_(h_mode), solver_(solver) {
  loop_shell::dunavant_rule(gauss_points);  // validates the count
}

LoopShellMethod::~LoopShellMethod() = default;

std::shared_ptr<LoopShellMethod::Cache> LoopShellMethod::cache_for(const Topology& topology) const {
  {
    std::lock_guard<std::mutex> lock(cache_mutex_);
    auto it = cache_.find(&topology);
    if (it != cache_.end() && it->second->matches(topology)) return it->second;
  }
  // Built outside the lock (it may take a while); a concurrent builder for the same topology
  // just does the same work once more.
  auto entry = std::make_shared<Cache>(topology, gauss_points_, control_ == Control::Solve, solver_ == Solver::LDLT);
  std::lock_guard<std::mutex> lock(cache_mutex_);
  if (cache_.size() >= kMaxCachedTopologies && !cache_.count(&topology)) cache_.erase(cache_.begin());
  cache_[&topology] = entry;
  return entry;
}

Points LoopShellMethod::control_points(const Topology& topology, const Points& x) const {
  if (x.rows() != topology.num_vertices())
    throw Error("method S: " + std::to_string(x.rows()) + " positions for " +
                std::to_string(topology.num_vertices()) + " vertices");
  if (control_ == Control::Nodes) return x;
  auto cache = cache_for(topology);
  return cache->limit_solver->solve(x);
}

loop_shell::ShellTerms LoopShellMethod::shell_terms(Cache& cache, const Points& control, const BendingParameters& p,
                                                    double* ade_energy) const {
  *ade_energy = 0;
  if (p.plain()) return loop_shell::ShellTerms(p.kappa_b);
  double lambda = 0;
  if (p.has_ade()) {
    const double m = loop_shell::shell_mean_curvature_integral(cache.patches, cache.bases, control);
    lambda = p.ade_lambda(m);
    *ade_energy = p.ade_energy(m);
  }
  return loop_shell::ShellTerms(p.kappa_b, p.c0, lambda);
}

double LoopShellMethod::control_energy(const Topology& topology, const Points& control, const BendingParameters& p,
                                       Points* gradient) const {
  auto cache = cache_for(topology);
  double ade = 0;
  const loop_shell::ShellTerms terms = shell_terms(*cache, control, p, &ade);
  return loop_shell::shell_energy(cache->patches, cache->bases, control, terms, gradient) + ade;
}

LoopShellState LoopShellMethod::state(const Topology& topology, const Points& x, const BendingParameters& p) const {
  auto cache = cache_for(topology);
  LoopShellState s;
  s.control = control_points(topology, x);
  Points gradient;
  SparseMatrix m = cache->mass.pattern();
  double ade = 0;
  const loop_shell::ShellTerms terms = shell_terms(*cache, s.control, p, &ade);
  s.energy = loop_shell::shell_energy_mass(cache->patches, cache->bases, cache->mass, cache->colouring, s.control,
                                           terms, gradient, m) + ade;
  s.control_force = -gradient;
  s.force_coefficients = solve_mass(*cache, m, Eigen::MatrixXd(s.control_force));
  return s;
}

void LoopShellMethod::evaluate(const Topology& topology, const Points& x, const BendingParameters& p,
                               bool nodal_geometry, BendingResult& r, Workspace& ws) const {
  if (x.rows() != topology.num_vertices())
    throw Error("method S: " + std::to_string(x.rows()) + " positions for " +
                std::to_string(topology.num_vertices()) + " vertices");
  std::shared_ptr<Cache> cache = cache_for(topology);
  if (ws.cache != cache) {  // another topology: the mass matrix's pattern (its values are assembled below)
    ws.m = cache->mass.pattern();
    ws.cache = cache;
  }
  const int nv = topology.num_vertices();
  // Step 1 (control_points).
  const Points& control = ws.control;
  if (control_ == Control::Nodes)
    ws.control = x;
  else
    cache->limit_solver->solve(x, ws.control, ws.limit_rhs, ws.limit_work);
  const bool project_h = nodal_geometry && h_mode_ == HMode::Projection;
  double ade = 0;
  const loop_shell::ShellTerms terms = shell_terms(*cache, control, p, &ade);
  r.energy = loop_shell::shell_energy_mass(cache->patches, cache->bases, cache->mass, cache->colouring, control,
                                           terms, ws.gradient, ws.m, project_h ? &ws.h_rhs : nullptr);
  if (!p.plain()) *r.energy += ade;
  Eigen::MatrixXd& rhs = ws.rhs;
  rhs.resize(nv, project_h ? 4 : 3);
  rhs.leftCols(3) = -ws.gradient;
  if (project_h) rhs.col(3) = ws.h_rhs;
  solve_mass(*cache, ws.m, rhs, ws);
  const Eigen::MatrixXd& solution = ws.solution;
  ws.fc = solution.leftCols(3);
  ws.product.noalias() = cache->limit * ws.fc;
  r.force_density = ws.product;
  mixed_area(topology, x, r.area, ws.corner_mixed);
  r.force = r.force_density.array().colwise() * r.area.array();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  r.lapH.setConstant(nv, nan);
  if (nodal_geometry) {
    loop_shell::limit_normals(topology, control, r.normal);
    loop_shell::limit_curvatures(topology, cache->patches, cache->curvature_bases, control, r.H, r.K);
    if (project_h) {
      ws.h_product.noalias() = cache->limit * solution.col(3);
      r.H = ws.h_product;
    }
  } else {
    r.normal.setConstant(nv, 3, nan);
    r.H.setConstant(nv, nan);
    r.K.setConstant(nv, nan);
  }
}

void LoopShellMethod::solve_mass(Cache& cache, const SparseMatrix& m, const Eigen::MatrixXd& b, Workspace& ws) const {
  if (solver_ == Solver::CG) {
    // The previous solution on this topology, when there is one of this size (else a cold start,
    // as solve_mass_cg does for it); `start` keeps its storage either way.
    ws.start.resize(b.rows(), b.cols());
    bool warm = false;
    {
      std::lock_guard<std::mutex> lock(cache.mutex);
      warm = cache.last_solution.rows() == b.rows() && cache.last_solution.cols() == b.cols();
      if (warm) ws.start = cache.last_solution;
    }
    loop_shell::solve_mass_cg(m, b, kCgTolerance, 10000, nullptr, warm ? &ws.start : nullptr, 2000, ws.cg,
                              ws.solution);
    std::lock_guard<std::mutex> lock(cache.mutex);
    cache.last_solution = ws.solution;
    return;
  }
  // (Eigen's factorisation and solve allocate their own temporaries.)
  std::lock_guard<std::mutex> lock(cache.mutex);
  cache.mass_ldlt.factorize(m);
  if (cache.mass_ldlt.info() != Eigen::Success) throw Error("method S: the mass matrix is not positive definite");
  ws.solution = cache.mass_ldlt.solve(b);
}

Eigen::MatrixXd LoopShellMethod::solve_mass(Cache& cache, const SparseMatrix& m, const Eigen::MatrixXd& b) const {
  if (solver_ == Solver::CG) {
    Eigen::MatrixXd start;
    {
      std::lock_guard<std::mutex> lock(cache.mutex);
      start = cache.last_solution;
    }
    Eigen::MatrixXd x = loop_shell::solve_mass_cg(m, b, kCgTolerance, 10000, nullptr, &start);
    std::lock_guard<std::mutex> lock(cache.mutex);
    cache.last_solution = x;
    return x;
  }
  std::lock_guard<std::mutex> lock(cache.mutex);
  cache.mass_ldlt.factorize(m);
  if (cache.mass_ldlt.info() != Eigen::Success) throw Error("method S: the mass matrix is not positive definite");
  return cache.mass_ldlt.solve(b);
}

BendingResult LoopShellMethod::compute(const Topology& topology, const Points& x, double kappa_b) const {
  BendingResult r;
  evaluate(topology, x, kappa_b, true, r, *workspace_.acquire());
  return r;
}

void LoopShellMethod::compute_into(const Topology& topology, const Points& x, double kappa_b,
                                   BendingResult& out) const {
  evaluate(topology, x, kappa_b, true, out, *workspace_.acquire());
}

void LoopShellMethod::forces(const Topology& topology, const Points& x, double kappa_b, Points& force) const {
  const auto ws = workspace_.acquire();
  evaluate(topology, x, kappa_b, false, ws->result, *ws);
  force = ws->result.force;
}

std::optional<double> LoopShellMethod::energy(const Topology& topology, const Points& x, double kappa_b) const {
  return control_energy(topology, control_points(topology, x), kappa_b);
}

BendingResult LoopShellMethod::compute_terms(const Topology& topology, const Points& x,
                                             const BendingParameters& p) const {
  BendingResult r;
  evaluate(topology, x, p, true, r, *workspace_.acquire());
  return r;
}

void LoopShellMethod::compute_terms_into(const Topology& topology, const Points& x, const BendingParameters& p,
                                         BendingResult& out) const {
  evaluate(topology, x, p, true, out, *workspace_.acquire());
}

void LoopShellMethod::forces_terms(const Topology& topology, const Points& x, const BendingParameters& p,
                                   Points& force) const {
  const auto ws = workspace_.acquire();
  evaluate(topology, x, p, false, ws->result, *ws);
  force = ws->result.force;
}

std::optional<double> LoopShellMethod::energy_terms(const Topology& topology, const Points& x,
                                                    const BendingParameters& p) const {
  return control_energy(topology, control_points(topology, x), p);
}

}  // namespace bendlab
