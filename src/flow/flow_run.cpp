#include "bendlab/flow/flow_run.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace bendlab {

nlohmann::json FlowRunSpec::to_json() const {
  const lbm::FlowUnitsInput& u = units;
  const bool tube = u.geometry == lbm::FlowGeometry::Tube;
  const bool shear = u.geometry == lbm::FlowGeometry::Shear;
  nlohmann::json j = {{"geometry", lbm::to_string(u.geometry)},
                      {"length_um", u.length_um},
                      {"dx_um", u.dx_um},
                      {"tau", u.tau},
                      {"plasma_viscosity", u.plasma.viscosity},
                      {"plasma_density", u.plasma.density},
                      {"seed", seed},
                      {"contact_cutoff_um", contact_cutoff_um},
                      {"contact_force", contact_force},
                      {"sample_every", sample_every},
                      {"steady_from", steady_from},
                      {"slice_width_um", slice_width_um}};
  j.update(cell.to_json());
  if (tube) {
    j["diameter_um"] = u.diameter_um;
  } else {
    j["height_um"] = u.height_um;
    j["width_um"] = u.width_um;
  }
  if (u.time_scale != 1) j["time_scale"] = u.time_scale;
  if (membrane_every != 1) j["membrane_every"] = membrane_every;  // absent when 1, as time_scale  // absent when 1: the runs made before it keep theirs
  if (u.pseudo_shear_rate) j["pseudo_shear_rate"] = *u.pseudo_shear_rate;
  if (shear && u.shear_rate) j["shear_rate"] = *u.shear_rate;
  if (u.body_force) j["body_force"] = *u.body_force;
  if (hematocrit) j["hematocrit"] = *hematocrit;
  if (cells) j["cells"] = *cells;
  return j;
}

namespace {

const FlowRunSpec& checked(const FlowRunSpec& s) {
  if (s.hematocrit && s.cells) throw Error("give --hematocrit or --cells, not both");
  if (s.hematocrit && (!std::isfinite(*s.hematocrit) || *s.hematocrit < 0 || *s.hematocrit >= 1))
    throw Error(fmt::format("--hematocrit {} must lie in [0, 1)", *s.hematocrit));
  if (s.cells && *s.cells < 0) throw Error(fmt::format("--cells {} must be >= 0", *s.cells));
  if (!(s.contact_cutoff_um >= 0) || !std::isfinite(s.contact_cutoff_um))
    throw Error(fmt::format("--contact-cutoff {} um must be >= 0 (0: one dx)", s.contact_cutoff_um));
  if (!(s.contact_force >= 0) || !std::isfinite(s.contact_force))
    throw Error(fmt::format("--contact-force {} N must be >= 0 (0: G_s dx)", s.contact_force));
  if (!(s.sample_every > 0) || !std::isfinite(s.sample_every))
    throw Error(fmt::format("--sample-every {} s must be positive", s.sample_every));
  if (!(s.steady_from >= 0 && s.steady_from < 1))
    throw Error(fmt::format("--steady-from {} must lie in [0, 1)", s.steady_from));
  if (s.membrane_every < 1) throw Error(fmt::format("--membrane-every {} must be at least 1", s.membrane_every));
  if (!(s.slice_width_um > 0) || !std::isfinite(s.slice_width_um))
    throw Error(fmt::format("--slice-width {} um must be positive", s.slice_width_um));
  return s;
}

Vessel vessel_of(const lbm::FlowUnitsInput& u, double scale) {
  if (u.geometry == lbm::FlowGeometry::Tube) return Vessel::tube(u.diameter_um * scale, u.length_um * scale);
  if (u.geometry == lbm::FlowGeometry::Shear)
    return Vessel::box(u.height_um * scale, u.width_um * scale, u.length_um * scale);
  return Vessel::channel(u.height_um * scale, u.width_um * scale, u.length_um * scale);
}

}  // namespace

FlowRun::FlowRun(const FlowRunSpec& spec, const std::function<void(const std::string&)>& note,
                 const SuspensionSolverFactory& make_solver)
    : spec_(checked(spec)), units_(lbm::flow_units(spec_.units)), kind_(make_cell_kind(spec_.cell)) {
  auto say = [&](const std::string& s) {
    if (note) note(s);
  };
  units_.checked_steps(spec_.sample_every, "--sample-every", true);
  // The cell-free flow (tubes and channels) is relaxed on the lattice before the run. It
  // develops over about (section / dx)^2 / nu_lattice steps: a lattice viscosity near 0 (tau near
  // 1/2) would take longer than any run should, refused here before the relaxation runs for
  // nothing (and checked again below where it did not settle).
  const double develop_steps = units_.section_lattice * units_.section_lattice / units_.nu_lattice;
  if (spec_.units.geometry != lbm::FlowGeometry::Shear && develop_steps > 10.0 * kMaxRelaxSteps)
    throw Error(fmt::format("--tau {}: the lattice viscosity (tau - 1/2)/3 = {:.3g} needs about {:.3g} lattice steps to "
                            "develop the cell-free flow across {:.4g} dx, far beyond the {} its relaxation may take: "
                            "raise --tau",
                            spec_.units.tau, units_.nu_lattice, develop_steps, units_.section_lattice, kMaxRelaxSteps));
  const double dx = spec_.units.dx_um;
  const bool shear = spec_.units.geometry == lbm::FlowGeometry::Shear;
  vessel_um_ = vessel_of(spec_.units, 1.0);
  const double cutoff_um = spec_.contact_cutoff_um > 0 ? spec_.contact_cutoff_um : dx;
  const double contact_force = spec_.contact_force > 0 ? spec_.contact_force : spec_.cell.shear_modulus * dx * 1e-6;

  // The cells, placed in um.
  const bool any_cells = (spec_.hematocrit && *spec_.hematocrit > 0) || (spec_.cells && *spec_.cells > 0);
  if (any_cells) {
    // An undeformed cell must fit the section to be placed: a tube takes a body of revolution
    // whose second largest extent (a disc's diameter, a prolate's width) is below D, a channel
    // one whose smallest extent is below H. The reference shape's axes are the frame's.
    const Points& ref = kind_.reference_um.positions();
    Vec3 extent = ref.colwise().maxCoeff() - ref.colwise().minCoeff();
    std::sort(extent.data(), extent.data() + 3);
    const bool tube_geometry = spec_.units.geometry == lbm::FlowGeometry::Tube;
    // The centred cell of a shear box stands as it is: its own z extent must fit.
    const double needed = tube_geometry ? extent[1]
                          : shear && spec_.cells == 1
                              ? ref.col(2).maxCoeff() - ref.col(2).minCoeff()
                              : extent[0];
    const double section = tube_geometry ? spec_.units.diameter_um : spec_.units.height_um;
    if (needed + 2 * 0.5 * cutoff_um >= section)
      throw Error(fmt::format("{} {} um is narrower than the cell: a {} of {} um across at best (its wall clearance "
                              "included) cannot be placed undeformed",
                              tube_geometry ? "--diameter" : "--height", section, spec_.cell.shape,
                              needed + cutoff_um));
    PlacementOptions p;
    p.hematocrit = spec_.hematocrit;
    p.count = spec_.cells;
    // Half the repulsion's cutoff: a quarter of the contact force at most as the run starts, and
    // room to place H_T 0.3 in a 10 um tube.
    p.clearance = 0.5 * cutoff_um;
    p.seed = spec_.seed;
    if (shear && spec_.cells == 1) {
      // One cell in the shear box sits where `bendlab shear --solver lbm` puts its capsule: its
      // volume centroid at the box centre, its axis along z, unrotated.
      placement_.cells.assign(1, PlacedCell{});
      placement_.cell_volume = kind_.volume_um3;
      placement_.hematocrit = kind_.volume_um3 / vessel_um_.volume();
    } else {
      placement_ = place_cells(vessel_um_, *kind_.reference_um.topology_ptr(), kind_.reference_um.positions(), p);
    }
    say(fmt::format("placed {} cells at tube hematocrit {:.4g} (seed {}, {} attempts{})", placement_.cells.size(),
                    placement_.hematocrit, spec_.seed, placement_.attempts,
                    placement_.initial_scale < 1 ? fmt::format("; grown from {:g} of their size in {} sweeps", placement_.initial_scale,
                                                               placement_.sweeps)
                                                 : std::string()));
  }

  SuspensionSolverOptions o;
  o.suspension.lattice = lbm::flow_lattice_config(units_);
  o.suspension.vessel = vessel_of(spec_.units, 1.0 / dx);
  const double force_lattice = units_.to_lattice_force(contact_force);
  o.suspension.cell_contact = ContactLaw{force_lattice, cutoff_um / dx};
  o.suspension.wall_contact = ContactLaw{force_lattice, cutoff_um / dx};
  o.suspension.membrane_every = spec_.membrane_every;
  o.dx_um = dx;
  o.dt_seconds = units_.dt;
  o.sample_every = spec_.sample_every;
  solver_ = make_solver ? make_solver(o) : std::make_unique<LbmSuspensionSolver>(o);

  // The cell-free flow on one whole lattice (on every process of a parallel run alike), handed to
  // the solver once it is set.
  lbm::Lattice lattice(o.suspension.lattice);
  if (shear) {
    // The walls' linear shear flow with its stress is a steady state of the lattice: no
    // relaxation, and no reference flow rate (the recorder reads the walls' stress instead).
    lattice.initialise_shear_flow();
    say(fmt::format("cell-free flow: the linear shear flow of the walls, {:.4g} 1/s", units_.pseudo_shear_rate));
    solver_->set_fluid(std::move(lattice));
    add_cells();
    return;
  }
  // The cell-free flow from the analytic Poiseuille profile, relaxed on the lattice.
  const bool tube = spec_.units.geometry == lbm::FlowGeometry::Tube;
  const double half = 0.5 * units_.section_lattice;  // R or H / 2 in dx
  const double v = units_.to_lattice_velocity(units_.mean_velocity);
  const double peak = tube ? 2 * v : 1.5 * v;
  lattice.initialise(
      [&](const Vec3& p) {
        const double s = tube ? (p.y() * p.y() + p.z() * p.z()) / (half * half) : p.z() * p.z() / (half * half);
        return Vec3(s < 1 ? peak * (1 - s) : 0.0, 0, 0);
      },
      nullptr,
      [&](const Vec3& p) {
        Mat3 S = Mat3::Zero();
        const double s = tube ? (p.y() * p.y() + p.z() * p.z()) / (half * half) : p.z() * p.z() / (half * half);
        if (s < 1) {
          if (tube) S(1, 0) = -2 * peak * p.y() / (half * half);
          S(2, 0) = -2 * peak * p.z() / (half * half);
        }
        return S;
      });
  double q = lattice_flow_rate(lattice, dx, units_.dt);
  constexpr std::int64_t kBlock = 100;
  constexpr double kSettled = 1e-9;  // relative change of Q over one block
  bool settled = false;
  double change = 0;
  while (relax_steps_ < kMaxRelaxSteps && !settled) {
    lattice.run(kBlock);
    relax_steps_ += kBlock;
    const double next = lattice_flow_rate(lattice, dx, units_.dt);
    change = std::abs(next - q) / std::abs(next);
    settled = change <= kSettled;
    q = next;
  }
  if (!(q > 0) || !std::isfinite(q))
    throw Error(fmt::format("the cell-free flow's rate is {} after {} steps: the lattice cannot carry this flow", q,
                            relax_steps_));
  // Unsettled, Q0 would not be the flow the cells start in.
  if (!settled)
    throw Error(fmt::format("--tau {}: the cell-free flow did not settle in {} lattice steps (its rate still changes "
                            "by {:.2g} per {} steps, {:.2g} allowed); the lattice viscosity (tau - 1/2)/3 = {:.3g} "
                            "needs about {:.3g} steps to develop the flow across {:.4g} dx: raise --tau",
                            spec_.units.tau, relax_steps_, change, kBlock, kSettled, units_.nu_lattice,
                            develop_steps, units_.section_lattice));
  q0_ = q;
  say(fmt::format("cell-free flow relaxed in {} steps: Q0 = {:.6g} um^3/s (mean velocity {:.4g} um/s, analytic {:.4g})",
                  relax_steps_, q0_, q0_ / (vessel_um_.volume() / vessel_um_.length()), units_.mean_velocity * 1e6));
  // The run starts at step 0 from the relaxed flow (the relaxation took a multiple of 100 steps,
  // so the populations are in the AA layout of an even step, as at step 0).
  lattice.restore_raw(lattice.raw_populations(), 0);
  solver_->set_fluid(std::move(lattice));
  add_cells();
}

double FlowRun::fluid_nodes() const {
  const lbm::LatticeConfig& c = solver_->options().suspension.lattice;
  double rows = 0;
  for (int k = 0; k < c.nz; ++k)
    for (int j = 0; j < c.ny; ++j) rows += solver_->solid_line(j, k) ? 0 : 1;
  return rows * c.nx;
}

void FlowRun::add_cells() {
  const std::shared_ptr<const MembraneModel> membrane = lattice_membrane(kind_, units_);
  for (const PlacedCell& c : placement_.cells)
    solver_->add_cell(membrane, placed_positions(kind_.reference_um.positions(), c));
}

std::vector<std::string> FlowRun::describe() const {
  std::vector<std::string> lines = units_.describe();
  const double R = spec_.cell.radius_um * 1e-6;
  // The capillary number of the cells: eta v R / (G_s D), v / D the pseudo-shear rate (in the
  // shear box the walls' shear rate gamma: eta gamma R / G_s).
  const double ca = spec_.units.plasma.viscosity * units_.pseudo_shear_rate * R / spec_.cell.shear_modulus;
  const bool shear = spec_.units.geometry == lbm::FlowGeometry::Shear;
  lines.push_back(fmt::format("cells: {} x {} ({}, {}; G_s = {:.3g} N/m, kappa_B = {:.3g} J, Method {}), "
                              "{} {:.4g}; capillary number {} = {:.3g}",
                              placement_.cells.size(), spec_.cell.shape, spec_.cell.mesh, spec_.cell.elastic_law,
                              spec_.cell.shear_modulus, spec_.cell.bending_modulus, spec_.cell.method,
                              shear ? "volume fraction" : "tube hematocrit", placement_.hematocrit,
                              shear ? "eta gamma R / G_s" : "eta (v/D) R / G_s", ca));
  lines.push_back(spec_.membrane_every == 1
                      ? std::string("membrane forces every lattice step (--membrane-every 1)")
                      : fmt::format("membrane forces every {} lattice steps, held in between (--membrane-every); "
                                    "contacts and motion every step; reports every {} steps",
                                    spec_.membrane_every, solver_->sample_steps()));
  return lines;
}

std::optional<std::string> FlowRun::warning() const { return mesh_leak_warning(kind_, spec_.units.dx_um); }

void FlowRun::check_end(const FlowRunSpec& spec, double t_end) {
  if (!(t_end > 0) || !std::isfinite(t_end)) throw Error(fmt::format("--t-end {} s must be positive", t_end));
  lbm::flow_units(spec.units).checked_steps(t_end, "--t-end");
}

CapsuleRunResult FlowRun::run(CapsuleRunOptions options) {
  check_end(spec_, options.t_end);
  nlohmann::json arguments = spec_.to_json();
  for (const auto& [key, value] : options.arguments.items()) arguments[key] = value;
  options.arguments = arguments;
  options.time_name = "t (s)";
  options.summary_fields["achieved_hematocrit_placed"] = placement_.hematocrit;
  options.summary_fields["relax_steps"] = relax_steps_;
  options.summary_fields["membrane_every"] = spec_.membrane_every;
  options.summary_fields["dt_s"] = units_.dt;
  options.summary_fields["mach"] = units_.mach;
  options.summary_fields["reynolds"] = units_.reynolds;
  SuspensionRecorderOptions r;
  r.vessel_um = vessel_um_;
  r.reference_flow_rate = q0_;
  r.slice_width_um = spec_.slice_width_um;
  r.steady_from = spec_.steady_from;
  SuspensionRecorder recorder(*solver_, r);
  return run_solver(*solver_, recorder, options);
}

}  // namespace bendlab
