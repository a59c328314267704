// The table of bending methods and the factory by name (method_registry.hpp).
#include "bendlab/bending/method_registry.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <deque>
#include <mutex>
#include <optional>

#include "bendlab/bending/belkin.hpp"
#include "bendlab/bending/farutin.hpp"
#include "bendlab/bending/gompper_kroll.hpp"
#include "bendlab/bending/julicher.hpp"
#include "bendlab/bending/kantor_nelson.hpp"
#include "bendlab/bending/loop_shell.hpp"
#include "bendlab/bending/meyer.hpp"
#include "bendlab/bending/mixed_ed.hpp"
#include "bendlab/bending/monge_jet.hpp"

namespace bendlab {

namespace {

/// The built-in methods, in the order of the paper's table 1 (then the conclusion's ED, then
/// section 2.5's S, then J and M, which are not in the paper).
/// A new built-in method adds its line here.
std::vector<MethodInfo> builtin_methods() {
  return {KantorNelson::info(), GompperKroll::info(), MeyerMethod::info(),
          BelkinMethod::info(), FarutinMethod::info(), MixedEDMethod::info(),
          LoopShellMethod::info(), JulicherMethod::info(), MongeJetMethod::info()};
}

bool valid_name(const std::string& name) {
  if (name.empty()) return false;
  for (char c : name)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-')) return false;
  return true;
}

std::optional<bool> parse_bool(const std::string& v) {
  if (v == "true" || v == "1" || v == "on" || v == "yes") return true;
  if (v == "false" || v == "0" || v == "off" || v == "no") return false;
  return std::nullopt;
}

// The whole string must be the number: no surrounding blanks, nothing after it.
std::optional<long> parse_long(const std::string& v) {
  if (v.empty() || std::isspace(static_cast<unsigned char>(v[0]))) return std::nullopt;
  errno = 0;
  char* end = nullptr;
  const long r = std::strtol(v.c_str(), &end, 10);
  if (errno != 0 || *end != '\0') return std::nullopt;
  return r;
}

std::optional<double> parse_double(const std::string& v) {
  if (v.empty() || std::isspace(static_cast<unsigned char>(v[0]))) return std::nullopt;
  errno = 0;
  char* end = nullptr;
  const double r = std::strtod(v.c_str(), &end);
  if (errno != 0 || *end != '\0' || !std::isfinite(r)) return std::nullopt;
  return r;
}

/// The value in normalised form, or throws naming the method and the option.
std::string check_value(const std::string& method, const OptionSpec& s, const std::string& value) {
  const std::string where = fmt::format("method {}: option '{}'", method, s.name);
  switch (s.type) {
    case OptionType::Bool: {
      const auto b = parse_bool(value);
      if (!b) throw Error(fmt::format("{} expects true or false, got '{}'", where, value));
      return *b ? "true" : "false";
    }
    case OptionType::Int: {
      const auto i = parse_long(value);
      if (!i || *i < s.min || *i > s.max)
        throw Error(fmt::format("{} must be an integer from {} to {}, got '{}'", where, s.min, s.max, value));
      return std::to_string(*i);
    }
    case OptionType::Real: {
      const auto r = parse_double(value);
      if (!r || *r < s.min || *r > s.max)
        throw Error(fmt::format("{} must be a number from {} to {}, got '{}'", where, s.min, s.max, value));
      return value;
    }
    case OptionType::Choice:
      for (const std::string& c : s.choices)
        if (c == value) return value;
      throw Error(fmt::format("{} must be one of {}, got '{}'", where, fmt::join(s.choices, ", "), value));
  }
  throw Error(where + ": invalid option type");
}

void check_info(const MethodInfo& info) {
  if (!valid_name(info.name))
    throw Error(fmt::format("bending method name '{}' is invalid (letters, digits, '_' or '-')", info.name));
  if (info.name == "none") throw Error("bending method name 'none' is reserved (no bending)");
  if (!info.factory) throw Error(fmt::format("bending method '{}' has no factory", info.name));
  for (std::size_t k = 0; k < info.options.size(); ++k) {
    const OptionSpec& s = info.options[k];
    if (!valid_name(s.name)) throw Error(fmt::format("method {}: option name '{}' is invalid", info.name, s.name));
    for (std::size_t l = 0; l < k; ++l)
      if (info.options[l].name == s.name)
        throw Error(fmt::format("method {}: option '{}' declared twice", info.name, s.name));
    if (s.type == OptionType::Choice && s.choices.empty())
      throw Error(fmt::format("method {}: option '{}' has no choices", info.name, s.name));
    check_value(info.name, s, s.default_value);  // the default must pass its own schema
  }
}

/// The table. A deque keeps references to entries valid while methods are added.
class Registry {
 public:
  static Registry& instance() {
    static Registry r;
    return r;
  }
  void add(MethodInfo info) {
    check_info(info);
    const std::lock_guard lock(mutex_);
    if (find_locked(info.name))
      throw Error(fmt::format("bending method '{}' is already registered", info.name));
    methods_.push_back(std::move(info));
  }
  const MethodInfo* find(const std::string& name) {
    const std::lock_guard lock(mutex_);
    return find_locked(name);
  }
  std::vector<MethodInfo> all() {
    const std::lock_guard lock(mutex_);
    return {methods_.begin(), methods_.end()};
  }

 private:
  Registry() {
    for (MethodInfo& m : builtin_methods()) {
      check_info(m);
      methods_.push_back(std::move(m));
    }
  }
  const MethodInfo* find_locked(const std::string& name) const {
    for (const MethodInfo& m : methods_)
      if (m.name == name) return &m;
    return nullptr;
  }
  std::mutex mutex_;
  std::deque<MethodInfo> methods_;
};

const std::string& required(const MethodOptions& o, const std::string& key) {
  const auto it = o.find(key);
  if (it == o.end()) throw Error(fmt::format("option '{}' missing (options not resolved against the schema)", key));
  return it->second;
}

}  // namespace

std::string to_string(OptionType type) {
  switch (type) {
    case OptionType::Bool: return "bool";
    case OptionType::Int: return "int";
    case OptionType::Real: return "real";
    case OptionType::Choice: return "choice";
  }
  throw Error("invalid OptionType value");
}

OptionSpec bool_option(std::string name, bool default_value, std::string help) {
  return {std::move(name), OptionType::Bool, default_value ? "true" : "false", std::move(help), 0, 0, {}};
}

OptionSpec int_option(std::string name, long min, long max, long default_value, std::string help) {
  return {std::move(name), OptionType::Int, std::to_string(default_value), std::move(help),
          static_cast<double>(min), static_cast<double>(max), {}};
}

OptionSpec real_option(std::string name, double min, double max, double default_value, std::string help) {
  return {std::move(name), OptionType::Real, fmt::format("{}", default_value), std::move(help), min, max, {}};
}

OptionSpec choice_option(std::string name, std::vector<std::string> choices, std::string default_value,
                         std::string help) {
  return {std::move(name), OptionType::Choice, std::move(default_value), std::move(help), 0, 0, std::move(choices)};
}

void register_bending_method(MethodInfo info) { Registry::instance().add(std::move(info)); }

std::vector<MethodInfo> bending_methods() { return Registry::instance().all(); }

std::vector<std::string> bending_method_names() {
  std::vector<std::string> names;
  for (const MethodInfo& m : bending_methods()) names.push_back(m.name);
  return names;
}

const MethodInfo* find_bending_method(const std::string& name) { return Registry::instance().find(name); }

const MethodInfo& bending_method_info(const std::string& name) {
  if (const MethodInfo* m = find_bending_method(name)) return *m;
  throw Error(fmt::format("unknown bending method '{}': expected one of {}", name,
                          fmt::join(bending_method_names(), ", ")));
}

MethodOptions resolve_method_options(const MethodInfo& info, const MethodOptions& options) {
  MethodOptions out;
  for (const auto& [key, value] : options) {
    const OptionSpec* spec = nullptr;
    for (const OptionSpec& s : info.options)
      if (s.name == key) spec = &s;
    if (!spec) {
      std::vector<std::string> known;
      for (const OptionSpec& s : info.options) known.push_back(s.name);
      throw Error(known.empty() ? fmt::format("method {}: unknown option '{}' (it takes none)", info.name, key)
                                : fmt::format("method {}: unknown option '{}' (known: {})", info.name, key,
                                              fmt::join(known, ", ")));
    }
    out[key] = check_value(info.name, *spec, value);
  }
  for (const OptionSpec& s : info.options)
    if (!out.count(s.name)) out[s.name] = check_value(info.name, s, s.default_value);
  return out;
}

MethodOptions options_for_method(const MethodInfo& info, const MethodOptions& options) {
  MethodOptions out;
  for (const OptionSpec& s : info.options)
    if (const auto it = options.find(s.name); it != options.end()) out.insert(*it);
  return out;
}

bool option_bool(const MethodOptions& resolved, const std::string& key) { return required(resolved, key) == "true"; }

long option_int(const MethodOptions& resolved, const std::string& key) {
  return std::strtol(required(resolved, key).c_str(), nullptr, 10);
}

double option_real(const MethodOptions& resolved, const std::string& key) {
  return std::strtod(required(resolved, key).c_str(), nullptr);
}

std::pair<std::string, std::string> parse_option_assignment(const std::string& text) {
  const auto eq = text.find('=');
  if (eq == std::string::npos || eq == 0)
    throw Error(fmt::format("--option: expected key=value, got '{}'", text));
  return {text.substr(0, eq), text.substr(eq + 1)};
}

std::unique_ptr<BendingMethod> make_bending_method(const std::string& name, const MethodOptions& options) {
  const MethodInfo& info = bending_method_info(name);
  return info.factory(resolve_method_options(info, options));
}

}  // namespace bendlab
