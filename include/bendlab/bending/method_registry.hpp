#pragma once
// The one table of bending methods (paper table 1): name, one-line description, factory, option
// schema and capabilities of every method. Everything that lists or chooses methods reads it: the
// factory make_bending_method(), the CLI (`bendlab methods`, the --method choices), the RBC study's
// default method list, the benchmarks and the tests that loop over all methods.
//
// Built-in methods (A, B, C, D, E, ED, S, J, M) are registered by the registry itself, from an explicit
// list in src/bending/method_registry.cpp, the first time the table is read; each method's file
// provides its entry (`static MethodInfo info()` beside `create()`). Adding a method is one new
// file plus one line in that list. Code outside the library adds methods at run time with
// register_bending_method() (or a namespace-scope BendingMethodRegistration object in an
// executable's own source: object files of a static library that nothing references are dropped
// by the linker, so the library itself never relies on self-registration).
//
// Option values are strings, as on a command line ({"rings", "2"}); make_bending_method() checks
// them against the method's schema, fills in the defaults and hands the factory the complete,
// normalised set (booleans as "true" / "false", integers and reals as given).
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "bendlab/bending/bending_method.hpp"

namespace bendlab {

enum class OptionType { Bool, Int, Real, Choice };

/// "bool", "int", "real", "choice".
std::string to_string(OptionType type);

/// One option of a method's schema.
struct OptionSpec {
  std::string name;                  ///< key in MethodOptions, e.g. "rings"
  OptionType type = OptionType::Bool;
  std::string default_value;         ///< normalised string form, e.g. "1", "false"
  std::string help;                  ///< one line
  double min = 0, max = 0;           ///< inclusive range of Int and Real options
  std::vector<std::string> choices;  ///< allowed values of a Choice option
};

/// Schema entries: a boolean (values true/false, 1/0, on/off, yes/no), an integer or a real in
/// [min, max], or one of `choices`.
OptionSpec bool_option(std::string name, bool default_value, std::string help);
OptionSpec int_option(std::string name, long min, long max, long default_value, std::string help);
OptionSpec real_option(std::string name, double min, double max, double default_value, std::string help);
OptionSpec choice_option(std::string name, std::vector<std::string> choices, std::string default_value,
                         std::string help);

/// What a method computes and what it costs.
struct MethodCapabilities {
  bool has_energy = false;     ///< E_B available, F = -dE/dx (BendingResult::energy set)
  bool defines_normal = true;  ///< BendingResult::normal is not NaN
  bool defines_H = true;       ///< BendingResult::H is not NaN
  bool defines_K = true;       ///< BendingResult::K is not NaN
  bool defines_lapH = true;    ///< BendingResult::lapH is not NaN
  /// The mesh must be free of obtuse triangles (or other admissibility conditions) for the
  /// method's operators to be consistent. No built-in method requires it.
  bool needs_admissible_mesh = false;
  std::string cost = "O(N)";   ///< time per evaluation in the number of vertices N
};

using MethodFactory = std::function<std::unique_ptr<BendingMethod>(const MethodOptions&)>;

/// One entry of the table.
struct MethodInfo {
  std::string name;          ///< letters, digits, '_' or '-', e.g. "ED"; used on command lines
  std::string description;   ///< one line
  std::vector<OptionSpec> options;
  MethodCapabilities capabilities;
  MethodFactory factory;     ///< receives the validated options with every default filled in
};

/// Adds a method to the table (after the built-ins). Throws bendlab::Error for an empty or
/// invalid name, a name already taken, a missing factory or an invalid option schema (an option
/// twice, a default its own schema refuses). Thread-safe.
void register_bending_method(MethodInfo info);

/// Registers a method when constructed: `const BendingMethodRegistration r{my_method_info()};` in
/// the source of an executable (not of a static library, see above).
struct BendingMethodRegistration {
  explicit BendingMethodRegistration(MethodInfo info) { register_bending_method(std::move(info)); }
};

/// Every registered method, built-ins first (A, B, C, D, E, ED, S, J, M), then in registration order.
/// A copy: the table may grow afterwards.
std::vector<MethodInfo> bending_methods();
/// The names of bending_methods(), in the same order.
std::vector<std::string> bending_method_names();
/// The entry of a method, or nullptr if no method has that name.
const MethodInfo* find_bending_method(const std::string& name);
/// The entry of a method; throws bendlab::Error naming the known methods for an unknown name.
const MethodInfo& bending_method_info(const std::string& name);

/// Checks `options` against the schema of `info` and returns them complete: every option of the
/// schema present (the default where not given), booleans as "true" / "false". Throws
/// bendlab::Error naming the method and the option: unknown option (listing the known ones),
/// a value of the wrong type, out of range or not among the choices.
MethodOptions resolve_method_options(const MethodInfo& info, const MethodOptions& options);

/// The subset of `options` whose keys belong to the method's schema (for options given once for
/// several methods, e.g. --rings for E and ED in the RBC study).
MethodOptions options_for_method(const MethodInfo& info, const MethodOptions& options);

/// Reads a validated option (after resolve_method_options).
bool option_bool(const MethodOptions& resolved, const std::string& key);
long option_int(const MethodOptions& resolved, const std::string& key);
double option_real(const MethodOptions& resolved, const std::string& key);

/// Parses "key=value" (a command line's --option); throws bendlab::Error for a missing '=' or key.
std::pair<std::string, std::string> parse_option_assignment(const std::string& text);

}  // namespace bendlab
