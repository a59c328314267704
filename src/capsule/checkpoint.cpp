#include "bendlab/capsule/checkpoint.hpp"

#include <fmt/format.h>

#include <cmath>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>

#include "bendlab/core/atomic_file.hpp"
#include "bendlab/core/file_input.hpp"

namespace bendlab {

namespace {
constexpr const char* kFormat = "bendlab capsule checkpoint";

struct Reader {
  const nlohmann::json& j;
  const std::string& source;

  [[noreturn]] void fail(const std::string& key, const std::string& expected) const {
    throw Error(fmt::format("{}: \"{}\" {}", source, key, expected));
  }
  const nlohmann::json& at(const std::string& key) const {
    if (!j.contains(key)) fail(key, "is missing");
    return j.at(key);
  }
  double number(const std::string& key, double min = -INFINITY) const {
    const auto& v = at(key);
    if (!v.is_number() || !std::isfinite(v.get<double>()) || v.get<double>() < min)
      fail(key, fmt::format("must be a finite number >= {}, got {}", min, v.dump()));
    return v.get<double>();
  }
  std::int64_t count(const std::string& key) const {
    const auto& v = at(key);
    if (!v.is_number_integer() || v.get<std::int64_t>() < 0)
      fail(key, fmt::format("must be a non-negative integer, got {}", v.dump()));
    return v.get<std::int64_t>();
  }
  const nlohmann::json& object(const std::string& key) const {
    const auto& v = at(key);
    if (!v.is_object()) fail(key, fmt::format("must be an object, got {}", v.type_name()));
    return v;
  }
  std::string string(const std::string& key) const {
    const auto& v = at(key);
    if (!v.is_string()) fail(key, fmt::format("must be a string, got {}", v.type_name()));
    return v.get<std::string>();
  }
};
}  // namespace

nlohmann::json CapsuleCheckpoint::to_json() const {
  std::vector<double> flat(positions.data(), positions.data() + positions.size());
  nlohmann::json j = {{"format", kFormat},
          {"version", kVersion},
          {"arguments", arguments},
          {"solver", solver},
          {"time", time},
          {"vertices", positions.rows()},
          {"positions", flat},
          {"steps", steps},
          {"wall_seconds", wall_seconds},
          {"counters", {{"rejected_steps", counters.rejected_steps}, {"velocity_evaluations", counters.velocity_evaluations}}},
          {"snapshots", snapshots},
          {"solver_state", solver_state.fields},
          {"side_files", solver_state.side_files}};
  if (final_for_t_end) j["final_for_t_end"] = *final_for_t_end;
  for (const auto& [key, value] : recorder.items()) {
    if (j.contains(key)) throw Error(fmt::format("checkpoint: the recorder's key \"{}\" is the checkpoint's own", key));
    j[key] = value;
  }
  return j;
}

CapsuleCheckpoint CapsuleCheckpoint::from_json(const nlohmann::json& j, int num_vertices, const std::string& source) {
  if (!j.is_object()) throw Error(fmt::format("{}: expected a JSON object, got {}", source, j.type_name()));
  const Reader r{j, source};
  if (!j.contains("version")) {
    if (j.contains("arguments") && j.at("arguments").is_object() && j.at("arguments").contains("kappa_b"))
      throw Error(fmt::format("{}: written by an older bendlab (no \"version\"; its \"kappa_b\" is the dimensionless "
                              "kappa_b_hat, and it lacks the counters and running sums); start the run again "
                              "without --resume",
                              source));
    r.fail("version", fmt::format("is missing (expected {})", kVersion));
  }
  if (!j.at("version").is_number_integer() || j.at("version").get<int>() != kVersion)
    r.fail("version", fmt::format("is {}, this bendlab reads version {}", j.at("version").dump(), kVersion));
  if (r.string("format") != kFormat) r.fail("format", fmt::format("must be \"{}\"", kFormat));

  CapsuleCheckpoint c;
  c.arguments = r.object("arguments");
  c.solver = r.string("solver");
  c.time = r.number("time", 0);
  const std::int64_t n = r.count("vertices");
  if (n != num_vertices) r.fail("vertices", fmt::format("is {}, the mesh has {} vertices", n, num_vertices));
  const auto& p = r.at("positions");
  if (!p.is_array() || static_cast<std::int64_t>(p.size()) != 3 * n)
    r.fail("positions", fmt::format("must be an array of {} numbers (3 per vertex), got {}", 3 * n,
                                    p.is_array() ? fmt::format("{} entries", p.size()) : std::string(p.type_name())));
  c.positions.resize(n, 3);
  for (std::size_t k = 0; k < p.size(); ++k) {
    if (!p[k].is_number() || !std::isfinite(p[k].get<double>()))
      r.fail("positions", fmt::format("entry {} is {}, expected a finite number", k, p[k].dump()));
    c.positions.data()[k] = p[k].get<double>();
  }
  c.steps = r.count("steps");
  c.wall_seconds = r.number("wall_seconds", 0);
  {
    const auto& cj = r.object("counters");
    for (const char* key : {"rejected_steps", "velocity_evaluations"})
      if (!cj.contains(key) || !cj.at(key).is_number_integer() || cj.at(key).get<std::int64_t>() < 0)
        r.fail(std::string("counters.") + key, "must be a non-negative integer");
    c.counters.rejected_steps = cj.at("rejected_steps").get<std::int64_t>();
    c.counters.velocity_evaluations = cj.at("velocity_evaluations").get<std::int64_t>();
  }
  const auto& s = r.at("snapshots");
  if (!s.is_array()) r.fail("snapshots", "must be an array of [time, file] pairs");
  static const std::regex name_re(R"(snapshot_\d{5,}\.vtp)");
  double previous = 0;
  for (std::size_t k = 0; k < s.size(); ++k) {
    const auto& e = s[k];
    if (!e.is_array() || e.size() != 2 || !e[0].is_number() || !e[1].is_string())
      r.fail("snapshots", fmt::format("entry {} must be [time, \"snapshot_NNNNN.vtp\"], got {}", k, e.dump()));
    const double t = e[0].get<double>();
    const std::string name = e[1].get<std::string>();
    if (!std::isfinite(t) || t < previous || t > c.time * (1 + 1e-12) + 1e-300)
      r.fail("snapshots", fmt::format("entry {} has time {}, expected increasing times up to the checkpoint's {}", k,
                                      t, c.time));
    if (!std::regex_match(name, name_re))
      r.fail("snapshots", fmt::format("entry {} names '{}', expected snapshot_NNNNN.vtp", k, name));
    previous = t;
    c.snapshots.emplace_back(t, name);
  }
  c.solver_state.fields = r.object("solver_state");
  const auto& sf = r.at("side_files");
  if (!sf.is_array()) r.fail("side_files", "must be an array of file names");
  for (const auto& f : sf) {
    if (!f.is_string() || f.get<std::string>().empty() || f.get<std::string>().find('/') != std::string::npos)
      r.fail("side_files", fmt::format("entry {} must be a plain file name in the run folder", f.dump()));
    c.solver_state.side_files.push_back(f.get<std::string>());
  }
  static const std::set<std::string> own = {"format",        "version",  "arguments", "solver",       "time",
                                            "vertices",      "positions", "steps",    "wall_seconds", "counters",
                                            "snapshots",     "solver_state", "side_files", "final_for_t_end"};
  for (const auto& [key, value] : j.items())
    if (!own.count(key)) c.recorder[key] = value;
  if (j.contains("final_for_t_end")) {
    c.final_for_t_end = r.number("final_for_t_end", 0);
    if (!(*c.final_for_t_end > 0) || *c.final_for_t_end > c.time * (1 + 1e-12) + 1e-12)
      r.fail("final_for_t_end", fmt::format("must be positive and at most the checkpoint's time {}, got {}", c.time,
                                            *c.final_for_t_end));
  }
  return c;
}

void CapsuleCheckpoint::write(const std::filesystem::path& path) const {
  AtomicFile f(path);
  f.stream() << to_json().dump();
  f.commit();
}

CapsuleCheckpoint CapsuleCheckpoint::parse(const std::string& text, int num_vertices, const std::string& source) {
  if (text.find_first_not_of(" \t\r\n") == std::string::npos)
    throw Error(fmt::format("{}: the checkpoint is empty", source));
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text);
  } catch (const nlohmann::json::parse_error& e) {
    throw Error(fmt::format("{}: not valid JSON (byte {})", source, e.byte));
  } catch (const nlohmann::json::exception& e) {  // e.g. a number beyond double's range
    throw Error(fmt::format("{}: not a valid checkpoint ({})", source, e.what()));
  }
  return from_json(j, num_vertices, source);
}

CapsuleCheckpoint CapsuleCheckpoint::read(const std::filesystem::path& path, int num_vertices) {
  return parse(read_regular_file(path, "the checkpoint"), num_vertices, path.string());
}

}  // namespace bendlab
