#include "method_cli.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

namespace bendlab::cli {

std::string method_names_joined(const std::string& separator) {
  return fmt::format("{}", fmt::join(bending_method_names(), separator));
}

std::vector<std::string> method_choices_with_none() {
  std::vector<std::string> names = bending_method_names();
  names.insert(names.begin(), "none");
  return names;
}

std::string method_choices_help() {
  std::vector<std::string> parts;
  for (const MethodInfo& m : bending_methods()) parts.push_back(fmt::format("{} ({})", m.name, m.description));
  return fmt::format("{}", fmt::join(parts, "; "));
}

void add_option_assignments(MethodOptions& options, const std::vector<std::string>& assignments) {
  for (const std::string& a : assignments) {
    auto [key, value] = parse_option_assignment(a);
    if (!options.emplace(key, value).second) throw Error(fmt::format("--option: option '{}' given twice", key));
  }
}

}  // namespace bendlab::cli
