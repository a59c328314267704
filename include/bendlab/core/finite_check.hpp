#pragma once
// Numerical health checks: the first row of a per-vertex array holding a NaN or an infinity, and
// an Error that names where it appeared. Used after every stage that produces forces, velocities
// or results (membrane model, BIM, bending methods in the CLI) so that a blow-up stops the work
// with a diagnosis instead of flowing on into later stages (where it surfaced as unrelated
// messages such as "the volume gradient vanishes").
#include <Eigen/Dense>
#include <fmt/format.h>

#include <cmath>
#include <string>

#include "bendlab/core/types.hpp"

namespace bendlab {

/// A non-finite value in a force, velocity, geometry or result (a kind of Error, so every caller
/// that reports Error reports it too).
class NonFiniteError : public Error {
 public:
  NonFiniteError(const std::string& message, Eigen::Index row) : Error(message), row_(row) {}
  /// The first row (vertex) holding a non-finite value.
  Eigen::Index row() const { return row_; }

 private:
  Eigen::Index row_;
};

/// The index of the first row of `a` holding a NaN or an infinity; -1 when every value is finite.
template <class Derived>
Eigen::Index first_non_finite_row(const Eigen::DenseBase<Derived>& a) {
  for (Eigen::Index i = 0; i < a.rows(); ++i)
    for (Eigen::Index j = 0; j < a.cols(); ++j)
      if (!std::isfinite(static_cast<double>(a(i, j)))) return i;
  return -1;
}

/// Throws NonFiniteError "<what> is not finite at vertex <i> (<row values>)" for the first
/// non-finite row of `a`; `what` names the quantity and the stage ("method E: the force F").
template <class Derived>
void require_finite_rows(const Eigen::DenseBase<Derived>& a, const std::string& what) {
  const Eigen::Index i = first_non_finite_row(a);
  if (i < 0) return;
  std::string values;
  for (Eigen::Index j = 0; j < a.cols(); ++j) {
    if (j > 0) values += ", ";
    values += std::to_string(static_cast<double>(a(i, j)));
  }
  throw NonFiniteError(what + " is not finite at vertex " + std::to_string(i) + " (" + values + ")", i);
}

/// Throws Error "<option> must be a finite number > 0, got <value>" (">= 0" with allow_zero) unless
/// value is finite and positive (or zero where allowed): the check of an input option or argument.
inline void require_positive(const std::string& option, double value, bool allow_zero = false) {
  if (std::isfinite(value) && value >= 0 && (allow_zero || value > 0)) return;
  throw Error(fmt::format("{} must be a finite number {} 0, got {}", option, allow_zero ? ">=" : ">", value));
}

}  // namespace bendlab
