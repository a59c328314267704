#include "bendlab/bending/loop_shell.hpp"

#include <Eigen/SparseCholesky>
#include <Eigen/SparseLU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <set>

#include "bendlab/bending/loop_shell_energy.hpp"
#include "bendlab/bending/loop_shell_limit.hpp"
#include "bendlab/bending/loop_shell_mass.hpp"
#include "bendlab/bending/loop_shell_patches.hpp"
#include "bendlab/bending/loop_shell_solve.hpp"
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
        mass(patches, t.num_vertices()) {
    if (solve_control) {
      limit_lu.compute(limit);
      if (limit_lu.info() != Eigen::Success) throw Error("method S: the limit-mask matrix L is singular");
    }
    if (factorize_mass) mass_ldlt.analyzePattern(mass.pattern());
  }
  bool matches(const Topology& t) const { return t.num_vertices() == num_vertices && t.faces() == faces; }

  int num_vertices;
  Faces faces;
  loop_shell::LoopPatches patches;
  loop_shell::QuadratureBases bases;
  SparseMatrix limit;
  loop_shell::MassPattern mass;
  std::mutex mutex;
  Eigen::SparseLU<SparseMatrix> limit_lu;
  Eigen::SimplicialLDLT<SparseMatrix> mass_ldlt;
};

namespace {

// Topologies whose caches are kept at once (a flow solver and a study use one or a few).
constexpr size_t kMaxCachedTopologies = 8;

}  // namespace

std::unique_ptr<BendingMethod> LoopShellMethod::create(const MethodOptions& options) {
  Control control = Control::Solve;
  int gauss = 6;
  HMode h = HMode::Limit;
  Solver solver = Solver::CG;
  for (const auto& [key, value] : options) {
    if (key == "control") {
      if (value == "solve")
        control = Control::Solve;
      else if (value == "nodes")
        control = Control::Nodes;
      else
        throw Error("method S: option 'control' expects solve or nodes, got '" + value + "'");
    } else if (key == "gauss") {
      if (value != "1" && value != "3" && value != "6" && value != "7" && value != "12")
        throw Error("method S: option 'gauss' expects 1, 3, 6, 7 or 12 points, got '" + value + "'");
      gauss = std::stoi(value);
    } else if (key == "H") {
      if (value == "limit")
        h = HMode::Limit;
      else if (value == "projection")
        h = HMode::Projection;
      else
        throw Error("method S: option 'H' expects limit or projection, got '" + value + "'");
    } else if (key == "solver") {
      if (value == "cg")
        solver = Solver::CG;
      else if (value == "ldlt")
        solver = Solver::LDLT;
      else
        throw Error("method S: option 'solver' expects cg or ldlt, got '" + value + "'");
    } else {
      throw Error("method S: unknown option '" + key + "' (known: control, gauss, H, solver)");
    }
  }
  return std::make_unique<LoopShellMethod>(control, gauss, h, solver);
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
  std::lock_guard<std::mutex> lock(cache->mutex);
  Eigen::MatrixXd p = cache->limit_lu.solve(Eigen::MatrixXd(x));
  return p;
}

double LoopShellMethod::control_energy(const Topology& topology, const Points& control, double kappa_b,
                                       Points* gradient) const {
  auto cache = cache_for(topology);
  return loop_shell::shell_energy(cache->patches, cache->bases, control, kappa_b, gradient);
}

LoopShellState LoopShellMethod::state(const Topology& topology, const Points& x, double kappa_b) const {
  auto cache = cache_for(topology);
  LoopShellState s;
  s.control = control_points(topology, x);
  Points gradient;
  s.energy = loop_shell::shell_energy(cache->patches, cache->bases, s.control, kappa_b, &gradient);
  s.control_force = -gradient;
  SparseMatrix m = cache->mass.pattern();
  cache->mass.assemble(cache->patches, cache->bases, s.control, m);
  s.force_coefficients = solve_mass(*cache, m, Eigen::MatrixXd(s.control_force));
  return s;
}

BendingResult LoopShellMethod::evaluate(const Topology& topology, const Points& x, double kappa_b,
                                        bool nodal_geometry) const {
  auto cache = cache_for(topology);
  const int nv = topology.num_vertices();
  BendingResult r;
  const Points control = control_points(topology, x);
  Points gradient;
  r.energy = loop_shell::shell_energy(cache->patches, cache->bases, control, kappa_b, &gradient);
  const bool project_h = nodal_geometry && h_mode_ == HMode::Projection;
  SparseMatrix m = cache->mass.pattern();
  Eigen::VectorXd h_rhs;
  cache->mass.assemble(cache->patches, cache->bases, control, m, project_h ? &h_rhs : nullptr);
  Eigen::MatrixXd rhs(nv, project_h ? 4 : 3);
  rhs.leftCols(3) = -gradient;
  if (project_h) rhs.col(3) = h_rhs;
  const Eigen::MatrixXd solution = solve_mass(*cache, m, rhs);
  const Eigen::MatrixXd fc = solution.leftCols(3);
  r.force_density = cache->limit * fc;
  r.area = MeshGeometry::compute(topology, x).mixed_area;
  r.force = r.force_density.array().colwise() * r.area.array();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  r.lapH = Scalars::Constant(nv, nan);
  if (nodal_geometry) {
    r.normal = loop_shell::limit_normals(topology, control);
    loop_shell::limit_curvatures(topology, cache->patches, control, r.H, r.K);
    if (project_h) r.H = cache->limit * solution.col(3);
  } else {
    r.normal = Points::Constant(nv, 3, nan);
    r.H = r.K = Scalars::Constant(nv, nan);
  }
  return r;
}

Eigen::MatrixXd LoopShellMethod::solve_mass(Cache& cache, const SparseMatrix& m, const Eigen::MatrixXd& b) const {
  if (solver_ == Solver::CG) return loop_shell::solve_mass_cg(m, b, kCgTolerance, 10000);
  std::lock_guard<std::mutex> lock(cache.mutex);
  cache.mass_ldlt.factorize(m);
  if (cache.mass_ldlt.info() != Eigen::Success) throw Error("method S: the mass matrix is not positive definite");
  return cache.mass_ldlt.solve(b);
}

BendingResult LoopShellMethod::compute(const Topology& topology, const Points& x, double kappa_b) const {
  return evaluate(topology, x, kappa_b, true);
}

void LoopShellMethod::forces(const Topology& topology, const Points& x, double kappa_b, Points& force) const {
  force = evaluate(topology, x, kappa_b, false).force;
}

std::optional<double> LoopShellMethod::energy(const Topology& topology, const Points& x, double kappa_b) const {
  return control_energy(topology, control_points(topology, x), kappa_b);
}

}  // namespace bendlab
