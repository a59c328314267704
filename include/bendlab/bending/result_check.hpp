#pragma once
// Numerical health of a bending method's result (core/finite_check.hpp): every quantity a method
// defines must be finite at every vertex. A quantity the method does not define is NaN at every
// vertex (bending_method.hpp) and is skipped; a quantity finite at some vertices and not at others
// is a failure of the method on this mesh, reported with the method, the quantity and the first
// vertex.
#include <string>

#include "bendlab/bending/bending_method.hpp"

namespace bendlab {

/// Throws NonFiniteError "method <name>: <quantity> is not finite at vertex <i> (...)" for the
/// first quantity (normal, H, K, lapH, F, f, area, energy) that is not finite where it is defined.
/// F, f and the area must be finite everywhere.
void require_finite_result(const BendingResult& r, const std::string& method);

}  // namespace bendlab
