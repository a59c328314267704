#pragma once
// The sensible range of the adaptive stepper's tolerances for a capsule run (units of
// shear_units.hpp: lengths in R, so atol is in R). The Cash-Karp controller keeps the local error
// of each step below atol + rtol |y|; with loose tolerances it takes steps that the membrane's
// stiff in-plane and bending forces do not allow and still accepts them, so the result drifts
// without any warning sign (rtol = atol = 0.1 gave D = 0.42 for a run whose D is 0.24).
//
//   rtol, atol > 1e-2          refused (the steady D and theta are not meaningful)
//   1e-4 < rtol or atol <= 1e-2  accepted with a warning (expect errors in D and theta of the
//                                order of the tolerance or larger)
//   rtol, atol <= 1e-4         accepted (defaults: rtol 1e-7, atol 1e-6)
#include <string>

namespace bendlab {

struct RunTolerances {
  static constexpr double kRefuseAbove = 1e-2;
  static constexpr double kWarnAbove = 1e-4;
};

/// Throws bendlab::Error naming the option (--rtol, --atol) for a tolerance that is not positive,
/// not finite or above RunTolerances::kRefuseAbove; returns a one-line warning for one above
/// kWarnAbove, and an empty string otherwise.
std::string check_run_tolerances(double rtol, double atol);

}  // namespace bendlab
