#include "bendlab/flow/lbm/physical_units.hpp"

#include <fmt/format.h>

#include <cmath>
#include <memory>

#include "bendlab/core/types.hpp"

namespace bendlab::lbm {

namespace {

void require_positive(double v, const char* what) {
  if (!(v > 0) || !std::isfinite(v)) throw Error(fmt::format("{} {} must be finite and positive", what, v));
}

// A size that must be a whole number of dx: its count of dx.
int whole_cells(double size_um, double dx_um, const char* option) {
  const double n = size_um / dx_um;
  const double r = std::round(n);
  if (std::abs(n - r) > 1e-6 || r < 1) {
    throw Error(fmt::format("{} {} um is not a whole number of dx = {} um ({} dx)", option, size_um, dx_um, n));
  }
  if (r > 1e6) throw Error(fmt::format("{} {} um is {} dx: too many lattice nodes", option, size_um, r));
  return static_cast<int>(r);
}

// The shear box: walls at z = -+H/2 moving with -+v, gamma = 2 v / H (the header).
FlowUnits shear_units(FlowUnits u) {
  const FlowUnitsInput& in = u.input;
  if (in.pseudo_shear_rate || in.body_force)
    throw Error("the shear box is driven by its walls: give --shear-rate (1/s), not --pseudo-shear-rate or --body-force");
  if (!in.shear_rate) throw Error("--shear-rate (1/s, the walls' shear rate) is required for --geometry shear");
  if (!(*in.shear_rate > 0) || !std::isfinite(*in.shear_rate))
    throw Error(fmt::format("--shear-rate {} must be finite and positive", *in.shear_rate));
  require_positive(in.length_um, "--length");
  require_positive(in.height_um, "--height");
  require_positive(in.width_um, "--width");
  u.nx = whole_cells(in.length_um, in.dx_um, "--length");
  u.ny = whole_cells(in.width_um, in.dx_um, "--width");
  u.nz = whole_cells(in.height_um, in.dx_um, "--height");
  if (u.nz < 4) throw Error(fmt::format("--height {} um is {} dx: a shear box needs at least 4 dx between its walls", in.height_um, u.nz));
  u.section_lattice = u.nz;
  const double dx = in.dx_um * 1e-6, H = in.height_um * 1e-6;
  u.nu = in.plasma.viscosity / in.lattice_density();
  u.nu_lattice = (in.tau - 0.5) / 3.0;
  u.dt = u.nu_lattice * dx * dx / u.nu;
  u.pseudo_shear_rate = *in.shear_rate;
  u.wall_velocity = 0.5 * u.pseudo_shear_rate * H;
  u.max_velocity_lattice = u.to_lattice_velocity(u.wall_velocity);
  u.mach = std::sqrt(3.0) * u.max_velocity_lattice;
  u.reynolds = u.wall_velocity * 0.5 * H / u.nu;
  if (!(u.mach <= in.max_mach)) {
    throw Error(fmt::format("Mach number {:.3g} (wall lattice velocity {:.3g}) exceeds {}: lower the shear rate, the "
                            "height, dx or tau",
                            u.mach, u.max_velocity_lattice, in.max_mach));
  }
  return u;
}

}  // namespace

std::string to_string(FlowGeometry geometry) {
  switch (geometry) {
    case FlowGeometry::Tube: return "tube";
    case FlowGeometry::Channel: return "channel";
    case FlowGeometry::Shear: return "shear";
  }
  return "unknown";
}

double FlowUnits::checked_steps(double s, const std::string& option, bool below_one_step_ok) const {
  const double steps = std::ceil(s / dt - 1e-9);
  const char* sets_dt = "set by --dx, --tau, --plasma-viscosity, --plasma-density and --time-scale";
  if (!(steps <= kMaxSteps))
    throw Error(fmt::format("{} {} s is {:.3g} lattice steps of dt = {:.4g} s ({}): more than the {:.3g} a run can "
                            "count",
                            option, s, s / dt, dt, sets_dt, kMaxSteps));
  if (!below_one_step_ok && !(steps >= 1))
    throw Error(fmt::format("{} {} s is shorter than one lattice step, dt = {:.4g} s ({})", option, s, dt, sets_dt));
  return steps;
}

double FlowUnits::to_lattice_force(double newtons) const {
  const double h = dx();
  return newtons * dt * dt / (input.lattice_density() * h * h * h * h);
}
double FlowUnits::to_lattice_modulus(double newtons_per_metre) const {
  const double h = dx();
  return newtons_per_metre * dt * dt / (input.lattice_density() * h * h * h);
}
double FlowUnits::to_lattice_energy(double joules) const {
  const double h = dx();
  return joules * dt * dt / (input.lattice_density() * h * h * h * h * h);
}

namespace {
// A time-scaled run keeps to Stokes flow: its Reynolds number is bounded (kMaxScaledReynolds).
void check_scaled_reynolds(const FlowUnits& u) {
  if (u.input.time_scale > 1 && !(u.reynolds <= kMaxScaledReynolds))
    throw Error(fmt::format("--time-scale {}: the Reynolds number {:.3g} ({:.3g} unscaled) exceeds {}, the bound within "
                            "which time scaling was measured to leave the flow's results unchanged; lower "
                            "--time-scale to at most {:.3g}",
                            u.input.time_scale, u.reynolds, u.reynolds / u.input.time_scale, kMaxScaledReynolds,
                            u.input.time_scale * kMaxScaledReynolds / u.reynolds));
}
}  // namespace

FlowUnits flow_units(const FlowUnitsInput& in) {
  FlowUnits u;
  u.input = in;
  require_positive(in.dx_um, "--dx");
  require_positive(in.plasma.viscosity, "plasma viscosity");
  require_positive(in.plasma.density, "plasma density");
  if (!(in.time_scale >= 1) || !std::isfinite(in.time_scale))
    throw Error(fmt::format("--time-scale {} must be a finite number >= 1", in.time_scale));
  if (!(in.tau > 0.5) || !std::isfinite(in.tau)) {
    throw Error(fmt::format("--tau {} must exceed 1/2 (the lattice viscosity (tau - 1/2)/3 must be positive)", in.tau));
  }
  require_positive(in.max_mach, "maximum Mach number");
  if (in.geometry == FlowGeometry::Shear) {
    const FlowUnits shear = shear_units(u);
    check_scaled_reynolds(shear);
    return shear;
  }
  if (in.shear_rate) throw Error("--shear-rate drives the shear box (--geometry shear); a tube or a channel takes --pseudo-shear-rate or --body-force");
  if (in.pseudo_shear_rate.has_value() == in.body_force.has_value()) {
    throw Error("give the driving either as --pseudo-shear-rate (1/s) or as --body-force (N/m^3), one of them");
  }
  if (in.pseudo_shear_rate && (!(*in.pseudo_shear_rate >= 0) || !std::isfinite(*in.pseudo_shear_rate))) {
    throw Error(fmt::format("--pseudo-shear-rate {} must be finite and not negative", *in.pseudo_shear_rate));
  }
  if (in.body_force && (!(*in.body_force >= 0) || !std::isfinite(*in.body_force))) {
    throw Error(fmt::format("--body-force {} must be finite and not negative", *in.body_force));
  }
  require_positive(in.length_um, "--length");
  u.nx = whole_cells(in.length_um, in.dx_um, "--length");
  const double eta = in.plasma.viscosity, dx = in.dx_um * 1e-6;
  double section = 0;  // D or H in m
  if (in.geometry == FlowGeometry::Tube) {
    require_positive(in.diameter_um, "--diameter");
    section = in.diameter_um * 1e-6;
    u.section_lattice = in.diameter_um / in.dx_um;
    if (u.section_lattice < 4) {
      throw Error(fmt::format("--diameter {} um is {} dx: a tube needs at least 4 dx across", in.diameter_um, u.section_lattice));
    }
    if (u.section_lattice > 1e5) throw Error(fmt::format("--diameter {} um is {} dx: too many lattice nodes", in.diameter_um, u.section_lattice));
    // Two solid rows at least on every side: every wall link ends in the solid, and an immersed
    // boundary's stencil near the wall reaches resting solid rows, not the far side of the box.
    u.ny = u.nz = static_cast<int>(std::ceil(u.section_lattice - 1e-9)) + 4;
  } else {
    require_positive(in.height_um, "--height");
    require_positive(in.width_um, "--width");
    const int H = whole_cells(in.height_um, in.dx_um, "--height");
    u.ny = whole_cells(in.width_um, in.dx_um, "--width");
    if (H < 4) throw Error(fmt::format("--height {} um is {} dx: a channel needs at least 4 dx across", in.height_um, H));
    u.nz = H + 4;  // two solid layers beyond each wall, as for the tube
    section = in.height_um * 1e-6;
    u.section_lattice = H;
  }
  u.nu = eta / in.lattice_density();
  u.nu_lattice = (in.tau - 0.5) / 3.0;
  u.dt = u.nu_lattice * dx * dx / u.nu;
  const double shape = in.geometry == FlowGeometry::Tube ? 32.0 : 12.0;  // v = g S^2 / (shape eta)
  if (in.pseudo_shear_rate) {
    u.pseudo_shear_rate = *in.pseudo_shear_rate;
    u.mean_velocity = u.pseudo_shear_rate * section;
    u.body_force = shape * eta * u.mean_velocity / (section * section);
  } else {
    u.body_force = *in.body_force;
    u.mean_velocity = u.body_force * section * section / (shape * eta);
    u.pseudo_shear_rate = u.mean_velocity / section;
  }
  u.body_force_lattice = u.body_force * u.dt * u.dt / (in.lattice_density() * dx);
  const double peak = in.geometry == FlowGeometry::Tube ? 2.0 : 1.5;
  u.max_velocity_lattice = peak * u.to_lattice_velocity(u.mean_velocity);
  u.mach = std::sqrt(3.0) * u.max_velocity_lattice;
  u.reynolds = u.mean_velocity * section / u.nu;
  if (!(u.mach <= in.max_mach)) {
    throw Error(fmt::format("Mach number {:.3g} (peak lattice velocity {:.3g}) exceeds {}: lower the driving, dx or tau",
                            u.mach, u.max_velocity_lattice, in.max_mach));
  }
  check_scaled_reynolds(u);
  return u;
}

std::string FlowUnits::time_scale_line() const {
  return fmt::format("time scale S = {:g}: the lattice works with rho = {:.4g} kg/m^3 (S times the plasma's), so dt is S "
                     "times longer and Re = {:.3g} ({:.3g} unscaled, at most {} allowed); times are physical seconds",
                     input.time_scale, input.lattice_density(), reynolds, reynolds / input.time_scale,
                     kMaxScaledReynolds);
}

std::vector<std::string> FlowUnits::describe() const {
  const bool tube = input.geometry == FlowGeometry::Tube;
  std::vector<std::string> lines;
  if (input.geometry == FlowGeometry::Shear) {
    lines.push_back(fmt::format("shear box {} um between its walls ({} dx), {} um wide, {} um long; lattice {} x {} x {} "
                                "nodes, dx = {} um",
                                input.height_um, nz, input.width_um, input.length_um, nx, ny, nz, input.dx_um));
    lines.push_back(fmt::format("plasma eta = {} Pa s, rho = {} kg/m^3 (nu = {:.4g} m^2/s); tau = {} (nu = {:.4g} dx^2/dt): dt = {:.4g} s",
                                input.plasma.viscosity, input.plasma.density, nu, input.tau, nu_lattice, dt));
    if (input.time_scale > 1) lines.push_back(time_scale_line());
    lines.push_back(fmt::format("driving: shear rate {:.4g} 1/s, walls moving with -+{:.4g} um/s ({:.4g} lattice)",
                                pseudo_shear_rate, wall_velocity * 1e6, max_velocity_lattice));
    lines.push_back(fmt::format("wall lattice velocity {:.4g}, Mach {:.3g}, Reynolds gamma H^2 / (4 nu) {:.3g}",
                                max_velocity_lattice, mach, reynolds));
    return lines;
  }
  lines.push_back(fmt::format("{} {} um across ({:.4g} dx), {} um long; lattice {} x {} x {} nodes, dx = {} um",
                              to_string(input.geometry), tube ? input.diameter_um : input.height_um, section_lattice,
                              input.length_um, nx, ny, nz, input.dx_um));
  lines.push_back(fmt::format("plasma eta = {} Pa s, rho = {} kg/m^3 (nu = {:.4g} m^2/s); tau = {} (nu = {:.4g} dx^2/dt): dt = {:.4g} s",
                              input.plasma.viscosity, input.plasma.density, nu, input.tau, nu_lattice, dt));
  if (input.time_scale > 1) lines.push_back(time_scale_line());
  lines.push_back(fmt::format("driving: pseudo-shear rate {:.4g} 1/s, body force {:.4g} N/m^3 ({:.4g} lattice), mean velocity {:.4g} um/s",
                              pseudo_shear_rate, body_force, body_force_lattice, mean_velocity * 1e6));
  lines.push_back(fmt::format("peak lattice velocity {:.4g}, Mach {:.3g}, Reynolds {:.3g}", max_velocity_lattice, mach, reynolds));
  return lines;
}

LatticeConfig flow_lattice_config(const FlowUnits& u) {
  LatticeConfig c;
  c.nx = u.nx;
  c.ny = u.ny;
  c.nz = u.nz;
  c.tau = u.input.tau;
  if (u.input.geometry == FlowGeometry::Shear) {
    c.walls = true;
    c.wall_velocity = u.max_velocity_lattice;
    c.collision = Collision::Auto;
    return c;
  }
  c.collision = Collision::TRT;
  c.body_force = Vec3(u.body_force_lattice, 0, 0);
  c.walls = false;
  if (u.input.geometry == FlowGeometry::Tube) {
    c.section = std::make_shared<TubeWall>(0.5 * u.section_lattice);
  } else {
    c.section = std::make_shared<SlabWall>(0.5 * u.section_lattice);
  }
  return c;
}

}  // namespace bendlab::lbm
