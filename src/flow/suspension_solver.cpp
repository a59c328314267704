#include "bendlab/flow/suspension_solver.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <utility>

#include "bendlab/flow/lbm/fluid_state.hpp"

namespace bendlab {

namespace {
const SuspensionSolverOptions& checked(const SuspensionSolverOptions& o) {
  for (const auto& [name, value] : {std::pair<const char*, double>{"dx", o.dx_um}, {"dt", o.dt_seconds},
                                    {"sample_every", o.sample_every}})
    if (!(value > 0) || !std::isfinite(value))
      throw Error(fmt::format("suspension solver: {} must be positive and finite, got {}", name, value));
  return o;
}
}  // namespace

SuspensionSolver::SuspensionSolver(SuspensionSolverOptions options)
    : options_(checked(options)),
      sample_steps_(std::max<std::int64_t>(1, std::llround(options_.sample_every / options_.dt_seconds))) {
  // Reports (and so checkpoints) at steps where the held membrane forces are renewed: a run
  // resumed there repeats the uninterrupted one.
  const std::int64_t every = options_.suspension.membrane_every;
  if (every > 1) sample_steps_ = (sample_steps_ + every - 1) / every * every;
  x_.resize(0, 3);
  u_.resize(0, 3);
}

const MembraneModel& SuspensionSolver::membrane() const {
  if (num_cells() == 0) throw Error("suspension solver: no cells");
  return cell_membrane(0);
}

nlohmann::json SuspensionSolver::summary() const {
  std::vector<const BendingMethod*> methods;
  for (int c = 0; c < num_cells(); ++c) {
    const BendingMethod* m = cell_membrane(c).bending();
    if (m && std::find(methods.begin(), methods.end(), m) == methods.end()) methods.push_back(m);
  }
  long fallbacks = 0;
  for (const BendingMethod* m : methods) fallbacks += m->fallback_count();
  return {{"bending_fallbacks", fallbacks}};
}

std::vector<SolverBody> SuspensionSolver::bodies() const {
  std::vector<SolverBody> b;
  b.reserve(static_cast<std::size_t>(num_cells()));
  for (int c = 0; c < num_cells(); ++c) b.push_back({&cell_membrane(c), cell_first_row(c)});
  return b;
}

int SuspensionSolver::add_cell(std::shared_ptr<const MembraneModel> lattice_membrane, const Points& X_um) {
  const int c = add_lattice_cell(std::move(lattice_membrane), X_um / options_.dx_um);
  sync_positions();
  return c;
}

void SuspensionSolver::sync_positions() {
  x_ = lattice_positions() * options_.dx_um;
  u_ = lattice_velocities();
}

bool SuspensionSolver::advance(double t_end, const OnStep& on_step) {
  // Whole lattice steps: the run ends at the first step at or beyond t_end.
  const auto end_step = static_cast<std::int64_t>(std::ceil(t_end / options_.dt_seconds - 1e-9));
  std::int64_t last_report = lattice_steps();
  while (lattice_steps() < end_step) {
    step_suspension();
    const std::int64_t n = lattice_steps();
    ++counters_.velocity_evaluations;
    if (n - last_fluid_check_ >= kFluidCheckSteps) {
      check_fluid();
      last_fluid_check_ = n;
    }
    if (n % sample_steps_ != 0 && n < end_step) continue;
    sync_positions();
    if (!on_step) {
      last_report = n;
      continue;
    }
    AcceptedStep s;
    s.time = time();
    // The run's end test compares times: the last step reports t_end itself when it lands there.
    if (n == end_step) s.time = std::max(s.time, t_end);
    s.dt = static_cast<double>(n - last_report) * options_.dt_seconds;
    s.positions = &x_;
    last_report = n;
    if (!on_step(s)) return false;
  }
  return true;
}

bool SuspensionSolver::is_side_file(const std::string& name) const { return lbm::is_fluid_file(name); }

SolverState SuspensionSolver::save_state(const std::filesystem::path& folder, const std::string& tag) const {
  check_fluid();  // never checkpoint a broken fluid
  SolverState s;
  const std::string fluid = lbm::fluid_file_name(tag);
  write_fluid(folder / fluid);
  s.side_files.push_back(fluid);
  s.fields = lbm::fluid_state_fields(fluid, lattice_steps(), lattice_positions());
  return s;
}

void SuspensionSolver::restore_state(const Points& positions, double time, const SolverCounters& counters,
                                     const nlohmann::json& fields, const std::filesystem::path& folder,
                                     const std::string& source) {
  auto bad = [&](const std::string& what) { return Error(fmt::format("{}: \"solver_state\": {}", source, what)); };
  const lbm::FluidStateFields saved = lbm::parse_fluid_state(fields, x_.rows(), source);
  const double t = static_cast<double>(saved.lattice_step) * options_.dt_seconds;
  if (std::abs(t - time) > 1e-9 * std::max(1.0, std::abs(time)) + options_.dt_seconds)
    throw bad(fmt::format("\"lattice_step\" {} is t = {} s, the checkpoint's time is {} s", saved.lattice_step, t, time));
  if (positions.rows() != saved.X.rows() ||
      (saved.X * options_.dx_um - positions).cwiseAbs().maxCoeff() > 1e-9 * std::max(1.0, positions.cwiseAbs().maxCoeff()))
    throw bad("\"positions_lattice\" do not match the checkpoint's positions");
  std::int64_t file_step = 0;
  try {
    file_step = read_state(folder / saved.fluid, saved.lattice_step, saved.X);
  } catch (const Error& e) {
    throw Error(fmt::format("{}: {}", source, e.what()));
  }
  if (file_step != saved.lattice_step)
    throw bad(fmt::format("the fluid file is at step {}, \"lattice_step\" is {}", file_step, saved.lattice_step));
  sync_positions();
  counters_ = counters;
  last_fluid_check_ = saved.lattice_step;
}

}  // namespace bendlab
