#include "bendlab/flow/lbm/fluid_state.hpp"

#include <fmt/format.h>

#include <cmath>
#include <regex>
#include <vector>

namespace bendlab::lbm {

bool is_fluid_file(const std::string& name) {
  static const std::regex fluid_re(R"(lbm_fluid_\d{5,}\.bin)");
  return std::regex_match(name, fluid_re);
}

std::string fluid_file_name(const std::string& tag) { return fmt::format("lbm_fluid_{}.bin", tag); }

nlohmann::json fluid_state_fields(const std::string& fluid, std::int64_t lattice_step, const Points& X) {
  return {{"fluid", fluid},
          {"lattice_step", lattice_step},
          {"positions_lattice", std::vector<double>(X.data(), X.data() + X.size())}};
}

FluidStateFields parse_fluid_state(const nlohmann::json& fields, Eigen::Index rows, const std::string& source) {
  auto bad = [&](const std::string& what) { return Error(fmt::format("{}: \"solver_state\": {}", source, what)); };
  if (!fields.is_object()) throw bad("must be an object");
  if (!fields.contains("fluid") || !fields.at("fluid").is_string()) throw bad("\"fluid\" must name the fluid file");
  FluidStateFields s;
  s.fluid = fields.at("fluid").get<std::string>();
  if (!is_fluid_file(s.fluid))
    throw bad(fmt::format("\"fluid\" is {}, expected lbm_fluid_NNNNN.bin", fields.at("fluid").dump()));
  if (!fields.contains("lattice_step") || !fields.at("lattice_step").is_number_integer() ||
      fields.at("lattice_step").get<std::int64_t>() < 0)
    throw bad("\"lattice_step\" must be an integer >= 0");
  s.lattice_step = fields.at("lattice_step").get<std::int64_t>();
  if (!fields.contains("positions_lattice") || !fields.at("positions_lattice").is_array() ||
      fields.at("positions_lattice").size() != static_cast<std::size_t>(3 * rows))
    throw bad(fmt::format("\"positions_lattice\" must hold {} numbers", 3 * rows));
  s.X.resize(rows, 3);
  for (Eigen::Index i = 0; i < s.X.size(); ++i) {
    const auto& v = fields.at("positions_lattice")[static_cast<std::size_t>(i)];
    if (!v.is_number() || !std::isfinite(v.get<double>())) throw bad("\"positions_lattice\" has a non-finite entry");
    s.X.data()[i] = v.get<double>();
  }
  return s;
}

}  // namespace bendlab::lbm
