#include "bendlab/capsule/run_tolerances.hpp"

#include <fmt/format.h>

#include <cmath>
#include <tuple>

#include "bendlab/core/types.hpp"

namespace bendlab {

std::string check_run_tolerances(double rtol, double atol) {
  std::string warning;
  for (const auto& [name, value, unit] : {std::tuple{"--rtol", rtol, ""}, std::tuple{"--atol", atol, " R"}}) {
    if (!(value > 0) || !std::isfinite(value))
      throw Error(fmt::format("{} must be a positive number, got {}", name, value));
    if (value > RunTolerances::kRefuseAbove)
      throw Error(fmt::format("{} {:g}{} is above {:g}: the stepper would accept steps far too large for the "
                              "membrane forces and the result would be wrong without notice",
                              name, value, unit, RunTolerances::kRefuseAbove));
    if (value > RunTolerances::kWarnAbove && warning.empty())
      warning = fmt::format("{} {:g}{} is above {:g}: expect errors in D and theta of the order of the tolerance or "
                            "larger (defaults: --rtol 1e-7, --atol 1e-6)",
                            name, value, unit, RunTolerances::kWarnAbove);
  }
  return warning;
}

}  // namespace bendlab
