#pragma once
// Error measures of the paper's eq. (17), docs/conventions.md §3.
//
// Per node i, with analytic (a) and numerical (n) values:
//   eps_n    = |n_a - n_n|                        (|n_a| = 1, so already relative)
//   eps_H    = |H_a - H_n| / max|H_a|             (likewise eps_K, eps_lapH)
//   eps_f    = |f_a - f_n| / max|f_a|             (Euclidean norm of the vector difference)
// The denominators are maxima over the whole analytic surface (SurfaceMaxima), not over the nodes.
// Summaries are the maximum and the plain (unweighted) average over the nodes.
//
// Not-available quantities: a method marks a quantity it does not define with NaN (or leaves the
// array empty). When every node error is NaN the quantity is "not available" (summary.available
// is false, studies skip it). When only some nodes are NaN the summary is NaN, so that a partly
// broken result is never hidden behind the maximum of the remaining nodes.
#include <array>
#include <string>

#include "bendlab/bending/bending_method.hpp"
#include "bendlab/core/types.hpp"
#include "bendlab/surfaces/analytic_surface.hpp"

namespace bendlab {

/// The compared quantities, in the order of the paper's tables (n first; it is not in table 2).
enum class Quantity { Normal, H, K, LapH, F };
inline constexpr std::array<Quantity, 5> kAllQuantities = {Quantity::Normal, Quantity::H, Quantity::K,
                                                           Quantity::LapH, Quantity::F};
/// "n", "H", "K", "lapH", "f" (the names of the CSV column `quantity`).
std::string to_string(Quantity q);
/// Inverse of to_string (exact spelling); throws bendlab::Error otherwise.
Quantity parse_quantity(const std::string& name);

/// eps_n per node: |a_i - n_i| (rows of N x 3 arrays).
Scalars normal_errors(const Points& analytic, const Points& numerical);
/// |a_i - n_i| / scale per node (eps_H, eps_K, eps_lapH). scale must be positive and finite.
Scalars scalar_errors(const Scalars& analytic, const Scalars& numerical, double scale);
/// |a_i - n_i| / scale per node, Euclidean norm of the row difference (eps_f).
Scalars vector_errors(const Points& analytic, const Points& numerical, double scale);

struct ErrorSummary {
  bool available = false;  ///< false: every node error is NaN or there are no nodes
  double max = 0;          ///< max_i eps_i (NaN when some but not all nodes are NaN)
  double average = 0;      ///< sum_i eps_i / N (NaN likewise)
};
ErrorSummary summarize(const Scalars& node_errors);

/// Per-node errors of every quantity. An entry is all NaN where the method does not define it.
struct NodeErrors {
  Scalars n, H, K, lapH, f;
  const Scalars& operator[](Quantity q) const;
};

/// eq. (17) for one method on one mesh: numerical.normal, H, K, lapH, force_density against the
/// analytic fields at the same nodes, relative to the analytic surface maxima. Arrays of the wrong
/// length throw bendlab::Error, except empty arrays, which count as not defined (all NaN).
/// Where an analytic field vanishes identically (Lap H and f on a sphere: maximum below 1e-9 of
/// the natural scale) the denominator is that natural scale instead: max|H|^3 for Lap H and
/// 2 |kB| max|H|^3 for f (kappa_b is the kB the fields were computed with).
NodeErrors node_errors(const SurfaceFields& analytic, const SurfaceMaxima& maxima,
                       const BendingResult& numerical, double kappa_b = 1.0);

}  // namespace bendlab
