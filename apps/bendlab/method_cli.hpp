#pragma once
// The bending methods on the command line, all read from the method registry
// (bendlab/bending/method_registry.hpp): the --method choices, their help text and the generic
// --option key=value flags.
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "bendlab/bending/method_registry.hpp"

namespace bendlab::cli {

/// The registered method names joined by `separator`: "A, B, C, D, E, ED, S".
std::string method_names_joined(const std::string& separator = ", ");
/// "none" followed by the registered method names (the --method choices of `bendlab shear`).
std::vector<std::string> method_choices_with_none();
/// "A (Kantor-Nelson: ...); B (...); ...": every method with its description, for --help.
std::string method_choices_help();
/// Adds the --option key=value assignments to `options`. Throws bendlab::Error for a malformed
/// assignment or a key given twice (also through a dedicated flag such as --rings).
void add_option_assignments(MethodOptions& options, const std::vector<std::string>& assignments);

/// --c0, --ade-alpha, --ade-d, --ade-da0 and (with_area) --ade-area: spontaneous curvature and
/// area-difference elasticity (docs/conventions.md §5).
struct MembraneTermArgs {
  double c0 = 0, ade_alpha = 0, ade_d = 0, ade_da0 = 0;
  std::optional<double> ade_area;
};
/// Adds the options to `cmd`; `units` ends each help line (e.g. " (units of 1/R)").
void add_membrane_term_options(CLI::App* cmd, MembraneTermArgs& args, bool with_area, const std::string& where);
/// The parameters for kB; ADE's area is --ade-area, else `default_area` (none: refused when ADE is
/// on). Throws bendlab::Error (one line) for invalid values, or ADE options without --ade-alpha.
BendingParameters membrane_parameters(double kappa_b, const MembraneTermArgs& args,
                                      std::optional<double> default_area = std::nullopt);

}  // namespace bendlab::cli
