#include "bendlab/flow/lbm/parameters.hpp"

#include <fmt/format.h>

#include <cmath>
#include <tuple>

#include "bendlab/flow/lbm/physical_units.hpp"

namespace bendlab::lbm {

LatticeConfig CapsuleRunParameters::lattice_config() const {
  LatticeConfig c;
  c.nx = nx;
  c.ny = ny;
  c.nz = nz;
  c.tau = tau;
  c.walls = true;
  c.wall_velocity = wall_velocity;
  return c;
}

CapsuleRunParameters capsule_run_parameters(const CapsuleRunInput& in) {
  if (!(in.radius > 0) || !std::isfinite(in.radius)) throw Error(fmt::format("capsule radius R = {} must be positive", in.radius));
  if (!(in.tau > 0.5) || !std::isfinite(in.tau)) {
    throw Error(fmt::format("LBM relaxation time tau = {} must exceed 1/2 (viscosity (tau - 1/2)/3 > 0)", in.tau));
  }
  if (!(in.reynolds > 0) || !std::isfinite(in.reynolds)) throw Error(fmt::format("Reynolds number {} must be positive", in.reynolds));
  if (!(in.G > 0) || !std::isfinite(in.G)) throw Error(fmt::format("capillary number G = {} must be positive", in.G));
  if (!(in.kB_hat >= 0) || !std::isfinite(in.kB_hat)) throw Error(fmt::format("bending modulus kB_hat = {} must be non-negative", in.kB_hat));
  if (!(in.gamma_t_end > 0)) throw Error(fmt::format("end time gamma t = {} must be positive", in.gamma_t_end));
  const double R = in.radius, h = ib_kernel_half_width(in.kernel);
  CapsuleRunParameters p;
  auto nodes = [&](double multiple, const char* axis) {
    if (!(multiple > 0) || !std::isfinite(multiple)) throw Error(fmt::format("box {} = {} R must be positive", axis, multiple));
    // Counted in double first: an int would overflow (and name a negative box) for a huge R.
    constexpr double kMaxNodes = 100000;
    const double n = std::round(multiple * R);
    if (n > kMaxNodes)
      throw Error(fmt::format("box {} = {} R of R = {} lattice units is {:.4g} nodes, more than the {:.0f} a lattice "
                              "takes along an axis (lower the radius in lattice units)",
                              axis, multiple, R, n, kMaxNodes));
    return static_cast<int>(n);
  };
  p.nx = nodes(in.box_x, "x");
  p.ny = nodes(in.box_y, "y");
  p.nz = nodes(in.box_z, "z");
  for (double e : in.half_extent)
    if (!(e > 0) || !std::isfinite(e)) throw Error(fmt::format("the capsule's half-extent {} R must be positive", e));
  // The capsule's extent along the axis (the sphere's diameter, a shape's own) plus the kernel
  // support on both sides must fit in a periodic period, or it overlaps its own image.
  for (auto [n, e, axis] : {std::tuple{p.nx, in.half_extent[0], "x"}, std::tuple{p.ny, in.half_extent[1], "y"}}) {
    if (n < 2.0 * (R * e + h)) {
      throw Error(fmt::format("box {} of {} nodes does not contain the capsule (extent {:.4g} plus kernel support {})",
                              axis, n, 2 * R * e, 2 * h));
    }
  }
  if (0.5 * p.nz <= R * in.half_extent[2] + h) {
    throw Error(fmt::format("capsule (reaching {:.4g} from its centre, plus kernel half-width {}) touches the walls at "
                            "z = +-{}",
                            R * in.half_extent[2], h, 0.5 * p.nz));
  }
  p.tau = in.tau;
  p.nu = (in.tau - 0.5) / 3.0;
  p.mu = p.nu;  // rho0 = 1
  p.reynolds = in.reynolds;
  p.wall_velocity = in.reynolds * p.nu / R;
  p.shear_rate = 2.0 * p.wall_velocity / p.nz;
  p.mach = p.wall_velocity * std::sqrt(3.0);
  if (p.mach > 0.1) {
    throw Error(fmt::format("wall Mach number {:.3g} exceeds 0.1 (lower Re = {} or raise tau)", p.mach, in.reynolds));
  }
  p.particle_reynolds = p.shear_rate * R * R / p.nu;
  p.kS = p.mu * p.shear_rate * R / in.G;
  p.kB = in.kB_hat * R * R * p.kS;
  p.kV = in.kV_over_kS * p.kS / R;  // kV = 100 kS in units of R (the header)
  const double steps = std::ceil(in.gamma_t_end / p.shear_rate);
  if (!(steps <= FlowUnits::kMaxSteps))
    throw Error(fmt::format("--t-end {} (gamma t) is {:.3g} lattice steps at a shear rate of {:.3g} per step: more than "
                            "the {:.3g} a run can count",
                            in.gamma_t_end, steps, p.shear_rate, FlowUnits::kMaxSteps));
  p.steps = static_cast<std::int64_t>(steps);
  if (in.reynolds > 0.3) {
    p.warnings.push_back(fmt::format("Reynolds number Re = R v / nu = {} is above the paper's bound 0.3", in.reynolds));
  }
  // tau near 1/2 makes nu and the wall speed, so the shear rate per lattice step, tiny: say what
  // the run will cost before it starts.
  constexpr double kManySteps = 1e7;
  if (static_cast<double>(p.steps) > kManySteps)
    p.warnings.push_back(fmt::format("the run takes {} lattice steps of {:.3g} nodes each to gamma t = {} (tau = {} "
                                     "makes the shear rate {:.3g} per step); expect a long run",
                                     p.steps, static_cast<double>(p.nx) * p.ny * p.nz, in.gamma_t_end, in.tau,
                                     p.shear_rate));
  if (p.mach > 0.01) p.warnings.push_back(fmt::format("wall Mach number {:.3g} is above the paper's 0.01", p.mach));
  return p;
}

}  // namespace bendlab::lbm
