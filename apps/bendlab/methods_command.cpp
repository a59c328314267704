// bendlab methods: the table of bending methods (method_registry.hpp): names, descriptions,
// options and capabilities, as text or as JSON (what the Python scripts read).
#include <fmt/format.h>

#include <iostream>
#include <nlohmann/json.hpp>

#include "bendlab/bending/method_registry.hpp"
#include "command.hpp"

namespace bendlab::cli {
namespace {

std::string format_number(double v) { return fmt::format("{}", v); }

nlohmann::ordered_json option_json(const OptionSpec& s) {
  nlohmann::ordered_json j = {
      {"name", s.name}, {"type", to_string(s.type)}, {"default", s.default_value}, {"help", s.help}};
  if (s.type == OptionType::Int) {
    j["min"] = static_cast<long>(s.min);
    j["max"] = static_cast<long>(s.max);
  } else if (s.type == OptionType::Real) {
    j["min"] = s.min;
    j["max"] = s.max;
  } else if (s.type == OptionType::Choice) {
    j["choices"] = s.choices;
  }
  return j;
}

nlohmann::ordered_json methods_json() {
  nlohmann::ordered_json out = nlohmann::ordered_json::array();
  for (const MethodInfo& m : bending_methods()) {
    nlohmann::ordered_json options = nlohmann::ordered_json::array();
    for (const OptionSpec& s : m.options) options.push_back(option_json(s));
    const MethodCapabilities& c = m.capabilities;
    out.push_back({{"name", m.name},
                   {"description", m.description},
                   {"options", options},
                   {"capabilities",
                    {{"has_energy", c.has_energy},
                     {"defines_normal", c.defines_normal},
                     {"defines_H", c.defines_H},
                     {"defines_K", c.defines_K},
                     {"defines_lapH", c.defines_lapH},
                     {"needs_admissible_mesh", c.needs_admissible_mesh},
                     {"cost", c.cost}}}});
  }
  return out;
}

std::string option_text(const OptionSpec& s) {
  std::string range;
  if (s.type == OptionType::Int || s.type == OptionType::Real)
    range = fmt::format(" {}..{}", format_number(s.min), format_number(s.max));
  else if (s.type == OptionType::Choice)
    range = " " + fmt::format("{}", fmt::join(s.choices, "|"));
  return fmt::format("{}={} ({}{}): {}", s.name, s.default_value, to_string(s.type), range, s.help);
}

void print_table() {
  std::cout << fmt::format("{:<6} {:<7} {:<7} {:<8} {}\n", "method", "energy", "fields", "cost", "description");
  for (const MethodInfo& m : bending_methods()) {
    const MethodCapabilities& c = m.capabilities;
    std::string fields;
    if (c.defines_normal) fields += "n";
    if (c.defines_H) fields += "H";
    if (c.defines_K) fields += "K";
    if (c.defines_lapH) fields += "L";
    std::cout << fmt::format("{:<6} {:<7} {:<7} {:<8} {}\n", m.name, c.has_energy ? "yes" : "no", fields, c.cost,
                             m.description);
    for (const OptionSpec& s : m.options) std::cout << fmt::format("{:<6}   --option {}\n", "", option_text(s));
  }
  std::cout << "fields: n normal, H mean curvature, K Gaussian curvature, L Laplace-Beltrami of H "
               "(the others are NaN)\n";
}

const CommandRegistration methods_registration([](CLI::App& app) {
  auto json = std::make_shared<bool>(false);
  auto* cmd = app.add_subcommand("methods", "List the bending methods: name, description, options (with type, "
                                            "range, default) and capabilities");
  cmd->add_flag("--json", *json, "print a JSON array (name, description, options, capabilities) instead of a table");
  cmd->callback([json] {
    if (*json)
      std::cout << methods_json().dump(1) << "\n";
    else
      print_table();
  });
});

}  // namespace
}  // namespace bendlab::cli
