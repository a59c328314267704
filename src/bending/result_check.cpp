#include "bendlab/bending/result_check.hpp"

#include <cmath>

#include "bendlab/core/finite_check.hpp"

namespace bendlab {

namespace {
template <class Derived>
bool all_nan(const Eigen::DenseBase<Derived>& a) {
  return a.size() > 0 && a.derived().array().isNaN().all();
}
}  // namespace

void require_finite_result(const BendingResult& r, const std::string& method) {
  const std::string who = "method " + method + ": ";
  // Quantities a method may leave undefined (NaN everywhere).
  if (!all_nan(r.normal)) require_finite_rows(r.normal, who + "the normal");
  if (!all_nan(r.H)) require_finite_rows(r.H, who + "the mean curvature H");
  if (!all_nan(r.K)) require_finite_rows(r.K, who + "the Gaussian curvature K");
  if (!all_nan(r.lapH)) require_finite_rows(r.lapH, who + "Lap H");
  // Quantities every method defines.
  require_finite_rows(r.force, who + "the node force F");
  require_finite_rows(r.force_density, who + "the force density f");
  require_finite_rows(r.area, who + "the mixed area");
  if (r.energy && !std::isfinite(*r.energy))
    throw NonFiniteError(who + "the bending energy is not finite", -1);
}

}  // namespace bendlab
