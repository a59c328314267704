#include "bendlab/flow/shear_run.hpp"

#include <fmt/format.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>

#include "bendlab/bending/method_registry.hpp"
#include "bendlab/geometry/measures.hpp"
#include "bendlab/capsule/run_tolerances.hpp"
#include "bendlab/capsule/shear_units.hpp"
#include "bendlab/core/file_input.hpp"
#include "bendlab/core/finite_check.hpp"
#include "bendlab/core/output_folder.hpp"
#include "bendlab/elasticity/elastic_law.hpp"
#include "bendlab/flow/bim/bim_capsule_solver.hpp"
#include "bendlab/flow/lbm/lbm_capsule_solver.hpp"
#include "bendlab/flow/lbm/physical_units.hpp"
#include "bendlab/membrane/espresso_volume_force.hpp"
#include "bendlab/integrate/cash_karp.hpp"
#include "bendlab/integrate/rkc.hpp"
#include "bendlab/mesh/mesh_spec.hpp"

namespace bendlab {

namespace fs = std::filesystem;

namespace {

std::string method_list() {
  std::string s;
  for (const std::string& n : bending_method_names()) s += (s.empty() ? "" : ", ") + n;
  return s;
}

/// A resumed run must use the law (and Skalak's C) it was started with. run_capsule compares every
/// argument too; this names the law in words before anything else is compared.
void check_resumed_membrane(const ShearRunSpec& a) {
  const fs::path path = a.folder / "checkpoint.json";
  // Read as a regular file only (a FIFO would block, a folder gives no text); the error names it.
  const nlohmann::json saved = nlohmann::json::parse(read_regular_file(path, "the checkpoint"), nullptr, false);
  if (saved.is_discarded() || !saved.is_object() || !saved.contains("arguments") || !saved["arguments"].is_object())
    return;  // run_capsule refuses an unreadable checkpoint with its own message
  const nlohmann::json& args = saved["arguments"];
  const std::string law = args.contains("membrane") && args["membrane"].is_string()
                              ? args["membrane"].get<std::string>() : "neo-hookean";
  const auto describe = [](const std::string& name, double c) {
    return name == "skalak" ? fmt::format("skalak with C = {}", c) : name;
  };
  const double c = args.contains("skalak_c") && args["skalak_c"].is_number() ? args["skalak_c"].get<double>()
                                                                               : kDefaultSkalakC;
  if (law != a.membrane || (law == "skalak" && c != a.skalak_c))
    throw Error(fmt::format("--resume: the run in '{}' was started with the membrane law {}, not {}; a run "
                            "cannot change its law",
                            a.folder.string(), describe(law, c), describe(a.membrane, a.skalak_c)));
}

}  // namespace

CapsuleRunResult run_shear(const ShearRunSpec& a, const ShearRunCallbacks& callbacks) {
  // Everything is checked before any work starts.
  if (a.solver != "bim" && a.solver != "lbm")
    throw Error(fmt::format("--solver '{}': the flow solvers are: bim, lbm", a.solver));
  if (a.solver == "lbm") {
    require_positive("--radius-lu", a.lattice.radius_lu);
    require_positive("--sample-every", a.lattice.sample_every);
    if (a.lattice.box.size() != 3) throw Error("--box needs three multiples of R: x,y,z");
    if (a.lattice.offset.size() != 3) throw Error("--offset needs three components in dx: x,y,z");
    for (double o : a.lattice.offset)
      if (!std::isfinite(o) || std::abs(o) > 1.0)
        throw Error(fmt::format("--offset {}: each component must be within [-1, 1] dx", o));
    if (a.lattice.kernel != "phi2" && a.lattice.kernel != "phi3" && a.lattice.kernel != "phi4")
      throw Error(fmt::format("--kernel '{}': the kernels are phi2, phi3, phi4", a.lattice.kernel));
    // tau, Re, the box and the walls are checked by lbm::capsule_run_parameters below, before any work.
  }
  require_positive("--G", a.G);
  if (a.kappa_b_hat) require_positive("--kappa-b-hat", *a.kappa_b_hat, true);
  if (a.kappa_b) require_positive("--kappa-b", *a.kappa_b, true);
  require_positive("--t-end", a.t_end);
  require_positive("--snapshot-every", a.snapshot_every);
  const std::string tolerance_warning = check_run_tolerances(a.rtol, a.atol);
  if (a.integrator != "cash-karp" && a.integrator != "rkc")
    throw Error(fmt::format("--integrator '{}': the integrators are: cash-karp, rkc", a.integrator));
  if (a.membrane != "neo-hookean" && a.membrane != "skalak")
    throw Error(fmt::format("--membrane '{}': the membrane laws are: neo-hookean, skalak", a.membrane));
  if (a.membrane == "skalak" && (!std::isfinite(a.skalak_c) || !(a.skalak_c > -0.5)))
    throw Error(fmt::format("--skalak-c must be a finite number > -1/2 (area modulus Gs (1 + 2C) > 0), got {}",
                            a.skalak_c));
  if (a.membrane != "skalak" && a.skalak_c != kDefaultSkalakC)
    throw Error("--skalak-c is for --membrane skalak");
  const SingleLayerQuadrature quadrature = single_layer_quadrature(a.bim_quadrature);
  if (a.solver != "bim" && a.bim_quadrature != "all7") throw Error("--bim-quadrature is for --solver bim");
  if (a.stop_after_steps < 0) throw Error("--stop-after-steps must be >= 0");
  if (a.max_steps < 0) throw Error("--max-steps must be >= 0");
  const ShearUnits units = ShearUnits::from(a.G, a.kappa_b_hat, a.kappa_b);
  if (a.method == "none" && units.kappa_b_hat > 0)
    throw Error("--kappa-b-hat or --kappa-b > 0 needs a bending --method (" + method_list() + ")");
  std::shared_ptr<const BendingMethod> bending;
  if (a.method != "none") bending = make_bending_method(a.method, a.method_options);
  else if (!a.method_options.empty()) throw Error("method options given without a bending --method");
  if (a.folder.empty()) throw Error("--out: no run folder given");
  if (fs::exists(a.folder) && !fs::is_directory(a.folder))
    throw Error(fmt::format("--out '{}' is a file, not a folder", a.folder.string()));
  const fs::path parent = parent_folder(a.folder);
  if (!fs::exists(a.folder) && !fs::is_directory(parent))
    throw Error(fmt::format("--out '{}': folder '{}' does not exist", a.folder.string(), parent.string()));
  if (a.resume && a.overwrite) throw Error("--resume and --overwrite exclude each other");
  if (a.resume && !fs::exists(a.folder / "checkpoint.json"))
    throw Error(fmt::format("--resume: no checkpoint in '{}' to resume from", a.folder.string()));
  check_capsule_shape(a.shape);
  if (a.resume) check_resumed_membrane(a);
  const CapsuleGeometry geometry = capsule_geometry(mesh_from_spec(a.mesh), a.shape);
  const TriMesh& mesh = geometry.reference;
  // c0 and ADE (docs/conventions.md §5), in units of R = 1; A defaults to the initial area.
  BendingParameters terms(1.0);
  terms.c0 = a.c0;
  terms.ade_alpha = a.ade_alpha;
  terms.ade_d = a.ade_d;
  terms.ade_da0 = a.ade_da0;
  if (terms.ade_alpha == 0 && (a.ade_d != 0 || a.ade_da0 != 0 || a.ade_area))
    throw Error("--ade-d, --ade-da0 and --ade-area need --ade-alpha > 0");
  if (terms.has_ade()) terms.ade_area = a.ade_area ? *a.ade_area : surface_area(mesh.topology(), geometry.initial);
  terms.validate();
  if (!terms.plain() && (a.method == "none" || !(units.kappa_b_hat > 0)))
    throw Error("--c0 and --ade-alpha need a bending --method and --kappa-b-hat (or --kappa-b) > 0");
  if (bending) {
    bending->check_parameters(terms);
    // One evaluation on the initial shape, so that a mesh the method refuses (Method S: two
    // extraordinary vertices in a triangle) fails here, before the run folder is written.
    Points probe;
    if (terms.plain())
      bending->forces(mesh.topology(), geometry.initial, 1.0, probe);
    else
      bending->forces(mesh.topology(), geometry.initial, terms, probe);
  }
  if (!tolerance_warning.empty() && callbacks.on_note) callbacks.on_note("warning: " + tolerance_warning);

  MembraneParameters mp;
  mp.kS = units.kS();
  mp.kB = units.kB();
  mp.bending = bending;
  mp.bending_terms = terms;
  mp.elastic_law = a.membrane;
  mp.skalak_c = a.skalak_c;
  std::unique_ptr<CapsuleSolver> solver;
  nlohmann::json lattice_arguments = nlohmann::json::object();
  nlohmann::json summary_fields = {{"rtol", a.rtol}, {"atol", a.atol}};
  double lattice_nodes = 0, lattice_gamma = 0;
  if (a.solver == "bim") {
    auto membrane = std::make_shared<const MembraneModel>(mesh, mp, geometry.initial);
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
    bim.quadrature.quadrature = quadrature;
    summary_fields["bim_quadrature"] = a.bim_quadrature;
    solver = std::make_unique<BimCapsuleSolver>(membrane, std::move(integrator), bim);
  } else {
    const LatticeRunSpec& l = a.lattice;
    lbm::CapsuleRunInput in;
    in.radius = l.radius_lu;
    in.tau = l.tau;
    in.box_x = l.box[0];
    in.box_y = l.box[1];
    in.box_z = l.box[2];
    in.reynolds = l.reynolds;
    in.G = units.G;
    in.kB_hat = units.kappa_b_hat;
    in.kV_over_kS = kEspressoVolumeRatio;
    in.gamma_t_end = a.t_end;
    in.kernel = l.kernel == "phi2" ? lbm::IbKernel::Phi2 : l.kernel == "phi3" ? lbm::IbKernel::Phi3 : lbm::IbKernel::Phi4;
    // The box must hold the shape as it starts, not only the sphere: a tilted prolate spheroid is
    // longer along x than 2 R. The sphere keeps its radius 1, as always.
    if (a.shape.shape != "sphere") {
      const Vec3 centre = volume_centroid(mesh.topology(), geometry.initial);
      for (int k = 0; k < 3; ++k)
        in.half_extent[static_cast<std::size_t>(k)] = (geometry.initial.col(k).array() - centre[k]).abs().maxCoeff();
    }
    const lbm::CapsuleRunParameters p = lbm::capsule_run_parameters(in);
    if (callbacks.on_note)
      for (const std::string& w : p.warnings) callbacks.on_note("warning: " + w);
    mp.volume_force = std::make_shared<const EspressoVolumeForce>(EspressoVolumeForce::for_membrane(mp.kS));
    auto membrane = std::make_shared<const MembraneModel>(mesh, mp, geometry.initial);
    LbmSolverOptions lo;
    lo.radius = l.radius_lu;
    lo.lattice = p;
    lo.kernel = in.kernel;
    lo.sample_every = l.sample_every;
    lo.offset = Vec3(l.offset[0], l.offset[1], l.offset[2]);
    // LbmCapsuleSolver's reporting interval (a parallel solver takes the same steps), a count the
    // run can hold (a larger one wrapped to a row every step).
    if (!(l.sample_every / p.shear_rate <= lbm::FlowUnits::kMaxSteps))
      throw Error(fmt::format("--sample-every {} (gamma t) is {:.3g} lattice steps: more than the {:.3g} a run can count",
                              l.sample_every, l.sample_every / p.shear_rate, lbm::FlowUnits::kMaxSteps));
    const auto sample_steps = std::max<std::int64_t>(1, std::llround(l.sample_every / p.shear_rate));
    if (callbacks.make_lbm_solver) {
      solver = callbacks.make_lbm_solver(membrane, lo);
    } else {
      solver = std::make_unique<LbmCapsuleSolver>(membrane, lo);
    }
    lattice_nodes = static_cast<double>(p.nx) * p.ny * p.nz;
    lattice_gamma = p.shear_rate;
    lattice_arguments = {{"radius_lu", l.radius_lu}, {"box", l.box},      {"tau", l.tau},
                         {"reynolds", l.reynolds},   {"kernel", l.kernel}, {"sample_every", l.sample_every},
                         {"kappa_v_over_kappa_s", kEspressoVolumeRatio}};
    // Only when given, so that the runs made before the option existed still resume.
    if (!lo.offset.isZero(0)) lattice_arguments["offset"] = l.offset;
    summary_fields = {{"lattice",
                       {{"nodes", {p.nx, p.ny, p.nz}},
                        {"nu", p.nu},
                        {"wall_velocity", p.wall_velocity},
                        {"shear_rate", p.shear_rate},
                        {"mach", p.mach},
                        {"reynolds", p.reynolds},
                        {"particle_reynolds", p.particle_reynolds},
                        {"kS", p.kS},
                        {"kB", p.kB},
                        {"kV", p.kV},
                        {"steps", p.steps},
                        {"sample_steps", sample_steps}}}};
  }

  CapsuleRunOptions o;
  o.folder = a.folder;
  o.t_end = a.t_end;
  o.snapshot_every = a.snapshot_every;
  o.resume = a.resume;
  o.overwrite = a.overwrite;
  o.stop_after_steps = a.stop_after_steps;
  // The capsule study takes the methods as published, net force and torque included (bendlab flow
  // removes them by default: docs/conventions.md §6).
  if (bending)
    o.start_notes.push_back(fmt::format("bending force: Method {}'s as the method gives it, its net force and torque "
                                        "kept (the paper's capsule study)",
                                        bending->name()));
  o.max_steps = a.max_steps;
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
  // Likewise neo-Hookean runs keep their identity; the Skalak law and its C are part of it, so a
  // run is never resumed under another law.
  if (a.membrane != "neo-hookean") {
    o.arguments["membrane"] = a.membrane;
    o.arguments["skalak_c"] = a.skalak_c;
  }
  // Likewise the quadrature: runs of the reference (all7) keep the identity they always had.
  if (a.bim_quadrature != "all7") o.arguments["bim_quadrature"] = a.bim_quadrature;
  // Likewise c0 and ADE: part of the identity only when used.
  if (terms.has_c0()) o.arguments["c0"] = terms.c0;
  if (terms.has_ade())
    o.arguments["ade"] = {{"alpha", terms.ade_alpha}, {"d", terms.ade_d}, {"dA0", terms.ade_da0}, {"A", terms.ade_area}};
  // Likewise the shape: the paper's sphere keeps the identity it always had; any other shape, tilt
  // or reference is part of it.
  if (!a.shape.is_default()) {
    o.arguments["shape"] = a.shape.shape;
    // An aspect not given is recorded as 0, as it always was (0 itself is refused).
    o.arguments["aspect"] = a.shape.aspect.value_or(0.0);
    o.arguments["tilt"] = a.shape.tilt_degrees;
    o.arguments["reference_shape"] = a.shape.reference;
    o.arguments["reference_aspect"] = a.shape.reference_aspect.value_or(0.0);
  }
  for (const auto& [key, value] : lattice_arguments.items()) o.arguments[key] = value;
  summary_fields["membrane_law"] = a.membrane;
  summary_fields["capsule_shape"] = geometry.description;
  if (a.membrane == "skalak") summary_fields["skalak_c"] = a.skalak_c;
  o.summary_fields = summary_fields;
  o.on_note = callbacks.on_note;
  if (callbacks.on_progress)
    o.on_progress = [&](const CapsuleProgress& progress) {
      CapsuleProgress p = progress;
      // Lattice node updates per second of this part (fluid + membrane + IBM).
      if (lattice_gamma > 0 && p.elapsed_seconds > 0)
        p.mlups = (p.time - p.t_start) / lattice_gamma * lattice_nodes / p.elapsed_seconds / 1e6;
      callbacks.on_progress(p);
    };
  o.should_stop = callbacks.should_stop;
  o.progress_interval_seconds = callbacks.progress_interval_seconds;
  o.writes_files = callbacks.writes_files;
  return run_capsule(*solver, o);
}

}  // namespace bendlab
