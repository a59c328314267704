#include "bendlab/flow/shear_run.hpp"

#include <fmt/format.h>

#include <cmath>

#include "bendlab/bending/method_registry.hpp"
#include "bendlab/capsule/shear_units.hpp"
#include "bendlab/flow/bim/bim_capsule_solver.hpp"
#include "bendlab/integrate/cash_karp.hpp"
#include "bendlab/integrate/rkc.hpp"
#include "bendlab/mesh/mesh_spec.hpp"

namespace bendlab {

namespace fs = std::filesystem;

namespace {

void require_positive(const std::string& option, double value, bool allow_zero = false) {
  if (!std::isfinite(value) || value < 0 || (!allow_zero && value == 0))
    throw Error(fmt::format("{} must be a finite number {} 0, got {}", option, allow_zero ? ">=" : ">", value));
}

std::string method_list() {
  std::string s;
  for (const std::string& n : bending_method_names()) s += (s.empty() ? "" : ", ") + n;
  return s;
}

}  // namespace

CapsuleRunResult run_shear(const ShearRunSpec& a, const ShearRunCallbacks& callbacks) {
  // Everything is checked before any work starts.
  if (a.solver != "bim") throw Error(fmt::format("--solver '{}': the flow solvers are: bim", a.solver));
  require_positive("--G", a.G);
  if (a.kappa_b_hat) require_positive("--kappa-b-hat", *a.kappa_b_hat, true);
  if (a.kappa_b) require_positive("--kappa-b", *a.kappa_b, true);
  require_positive("--t-end", a.t_end);
  require_positive("--snapshot-every", a.snapshot_every);
  require_positive("--rtol", a.rtol);
  require_positive("--atol", a.atol);
  if (a.integrator != "cash-karp" && a.integrator != "rkc")
    throw Error(fmt::format("--integrator '{}': the integrators are: cash-karp, rkc", a.integrator));
  if (a.stop_after_steps < 0) throw Error("--stop-after-steps must be >= 0");
  const ShearUnits units = ShearUnits::from(a.G, a.kappa_b_hat, a.kappa_b);
  if (a.method == "none" && units.kappa_b_hat > 0)
    throw Error("--kappa-b-hat or --kappa-b > 0 needs a bending --method (" + method_list() + ")");
  std::shared_ptr<const BendingMethod> bending;
  if (a.method != "none") bending = make_bending_method(a.method, a.method_options);
  else if (!a.method_options.empty()) throw Error("method options given without a bending --method");
  if (a.folder.empty()) throw Error("--out: no run folder given");
  if (fs::exists(a.folder) && !fs::is_directory(a.folder))
    throw Error(fmt::format("--out '{}' is a file, not a folder", a.folder.string()));
  if (a.resume && !fs::exists(a.folder / "checkpoint.json"))
    throw Error(fmt::format("--resume: no checkpoint in '{}' to resume from", a.folder.string()));
  const TriMesh mesh = mesh_from_spec(a.mesh);

  MembraneParameters mp;
  mp.kS = units.kS();
  mp.kB = units.kB();
  mp.bending = bending;
  auto membrane = std::make_shared<const MembraneModel>(mesh, mp);
  std::unique_ptr<Integrator> integrator;
  if (a.integrator == "rkc") {
    RkcOptions rk;
    rk.rtol = a.rtol;
    rk.atol = a.atol;
    integrator = std::make_unique<Rkc>(rk);
  } else {
    CashKarpOptions ck;
    ck.rtol = a.rtol;
    ck.atol = a.atol;
    integrator = std::make_unique<CashKarp>(ck);
  }
  BimOptions bim;
  bim.mu = ShearUnits::mu;
  bim.gamma = ShearUnits::gamma;
  BimCapsuleSolver solver(membrane, std::move(integrator), bim);

  CapsuleRunOptions o;
  o.folder = a.folder;
  o.t_end = a.t_end;
  o.snapshot_every = a.snapshot_every;
  o.resume = a.resume;
  o.stop_after_steps = a.stop_after_steps;
  // The run's identity (checked on resume): every option given; "rings" also on its own, as the
  // command line has always recorded it (the value given, 0 for the method's default).
  const auto rings = a.method_options.find("rings");
  o.arguments = {{"solver", a.solver},
                 {"method", a.method},
                 {"rings", rings == a.method_options.end() ? 0 : std::stoi(rings->second)},
                 {"mesh", a.mesh},
                 {"G", units.G},
                 {"kappa_b_hat", units.kappa_b_hat},
                 {"kappa_b", units.kappa_b()},
                 {"method_options", a.method_options}};
  // Cash-Karp runs keep the identity they had before the integrator could be chosen, so their
  // checkpoints still resume; another integrator is part of the identity.
  if (a.integrator != "cash-karp") o.arguments["integrator"] = a.integrator;
  o.summary_fields = {{"rtol", a.rtol}, {"atol", a.atol}};
  o.on_note = callbacks.on_note;
  o.on_progress = callbacks.on_progress;
  o.should_stop = callbacks.should_stop;
  o.progress_interval_seconds = callbacks.progress_interval_seconds;
  return run_capsule(solver, o);
}

}  // namespace bendlab
