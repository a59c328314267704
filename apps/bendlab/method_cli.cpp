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

void add_membrane_term_options(CLI::App* cmd, MembraneTermArgs& a, bool with_area, const std::string& where) {
  cmd->add_option("--c0", a.c0,
                  "spontaneous curvature c0, same sign as H (E = 2 kB int (H - c0)^2 dA; docs/conventions.md §5)" +
                      where)
      ->capture_default_str();
  cmd->add_option("--ade-alpha", a.ade_alpha,
                  "area-difference elasticity: alpha = k_ADE / kB >= 0 (0: none), "
                  "E_ADE = alpha kB pi / (8 A d^2) (2 d int H dA - dA0)^2")
      ->capture_default_str();
  cmd->add_option("--ade-d", a.ade_d, "ADE: leaflet distance d > 0" + where);
  cmd->add_option("--ade-da0", a.ade_da0, "ADE: preferred area difference dA0 (default 0)" + where);
  if (with_area) cmd->add_option("--ade-area", a.ade_area, "ADE: membrane area A > 0 of the ADE coefficient" + where);
}

BendingParameters membrane_parameters(double kappa_b, const MembraneTermArgs& a, std::optional<double> default_area) {
  BendingParameters p(kappa_b);
  p.c0 = a.c0;
  p.ade_alpha = a.ade_alpha;
  p.ade_d = a.ade_d;
  p.ade_da0 = a.ade_da0;
  if (p.ade_alpha == 0 && (a.ade_d != 0 || a.ade_da0 != 0 || a.ade_area))
    throw Error("--ade-d, --ade-da0 and --ade-area need --ade-alpha > 0");
  if (p.has_ade()) {
    if (a.ade_area)
      p.ade_area = *a.ade_area;
    else if (default_area)
      p.ade_area = *default_area;
    else
      throw Error("--ade-alpha needs --ade-area (the membrane area A of the ADE coefficient)");
  }
  p.validate();
  return p;
}

}  // namespace bendlab::cli
