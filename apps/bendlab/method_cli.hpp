#pragma once
// The bending methods on the command line, all read from the method registry
// (bendlab/bending/method_registry.hpp): the --method choices, their help text and the generic
// --option key=value flags.
#include <string>
#include <vector>

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

}  // namespace bendlab::cli
