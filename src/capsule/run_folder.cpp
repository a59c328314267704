#include "bendlab/capsule/run_folder.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <regex>
#include <set>

#include "bendlab/capsule/checkpoint.hpp"
#include "bendlab/core/atomic_file.hpp"
#include "bendlab/core/types.hpp"

namespace fs = std::filesystem;

namespace bendlab {

RunFolder::RunFolder(fs::path folder, NamePredicate recorder_output, NamePredicate side_file)
    : folder_(std::move(folder)), recorder_output_(std::move(recorder_output)), side_file_(std::move(side_file)) {}

bool RunFolder::is_output(const std::string& name) const {
  // D_theta.png is the command line's plot of a capsule run; it belongs to the run as much as the
  // files it is drawn from.
  static const std::set<std::string> fixed = {"checkpoint.json", "summary.json", "timing.json", "shapes.pvd",
                                              "D_theta.png"};
  static const std::regex snapshot_re(R"(snapshot_\d{5,}\.vtp)");
  return fixed.count(name) > 0 || std::regex_match(name, snapshot_re) || recorder_output_(name) || side_file_(name);
}

bool RunFolder::is_run_file(const std::string& name) const {
  if (is_output(name)) return true;
  if (const std::optional<std::string> target = atomic_temp_target(name)) return is_output(*target);
  static const std::string bare = ".tmp";
  return name.size() > bare.size() && name.compare(name.size() - bare.size(), bare.size(), bare) == 0 &&
         side_file_(name.substr(0, name.size() - bare.size()));
}

void RunFolder::lock(bool resume) {
  if (!resume && !fs::exists(folder_)) {
    std::error_code ec;
    fs::create_directory(folder_, ec);
    if (ec && !fs::is_directory(folder_))
      throw Error(fmt::format("cannot create the run folder '{}': {}", folder_.string(), ec.message()));
  }
  if (fs::is_directory(folder_)) lock_.emplace(folder_, "run folder");
}

// The names of the run's files (temporaries included; folders are no run's), sorted.
std::vector<std::string> RunFolder::run_files(bool temporaries_only) const {
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(folder_)) {
    const std::string name = entry.path().filename().string();
    if (entry.is_directory() && !entry.is_symlink()) continue;
    if (!is_run_file(name)) continue;
    if (temporaries_only && is_output(name)) continue;
    names.push_back(name);
  }
  std::sort(names.begin(), names.end());
  return names;
}

void RunFolder::remove(const std::vector<std::string>& names) const {
  for (const std::string& name : names) {
    std::error_code ec;
    fs::remove(folder_ / name, ec);
    if (ec) throw Error(fmt::format("cannot remove '{}': {}", (folder_ / name).string(), ec.message()));
  }
}

void RunFolder::clear_for_new_run(bool overwrite) const {
  const std::vector<std::string> old = run_files(false);
  if (!old.empty() && !overwrite)
    throw Error(fmt::format("'{}' holds another run ('{}'{}); continue it with --resume, or replace it with "
                            "--overwrite",
                            folder_.string(), old.front(),
                            old.size() > 1 ? fmt::format(" and {} more", old.size() - 1) : std::string()));
  remove(old);
}

void RunFolder::remove_temporaries() const { remove(run_files(true)); }

void RunFolder::check_snapshots(const CapsuleCheckpoint& c, const std::string& source) const {
  if (c.snapshots.empty())
    throw Error(fmt::format("{}: \"snapshots\" is empty; a checkpoint is written with a snapshot, so it lists one at "
                            "least",
                            source));
  for (std::size_t k = 0; k < c.snapshots.size(); ++k) {
    const std::string expected = fmt::format("snapshot_{:05d}.vtp", k);
    if (c.snapshots[k].second != expected)
      throw Error(fmt::format("{}: \"snapshots\" entry {} names '{}', expected '{}'", source, k, c.snapshots[k].second,
                              expected));
  }
  static const std::regex snapshot_re(R"(snapshot_(\d{5,})\.vtp)");
  for (const auto& entry : fs::directory_iterator(folder_)) {
    const std::string name = entry.path().filename().string();
    std::smatch m;
    if (std::regex_match(name, m, snapshot_re) && m[1].str().size() < 10 &&
        std::stoll(m[1].str()) > static_cast<long long>(c.snapshots.size()))
      throw Error(fmt::format("{}: \"snapshots\" lists {} snapshots but '{}' holds '{}', a later one; the resumed run "
                              "would overwrite it",
                              source, c.snapshots.size(), folder_.string(), name));
  }
  const double last = c.snapshots.back().first;
  if (std::abs(last - c.time) > 1e-12 * std::max(1.0, std::abs(c.time)))
    throw Error(fmt::format("{}: the last of \"snapshots\" is at gamma t = {}, the checkpoint's \"time\" is {}",
                            source, last, c.time));
}

void RunFolder::write_json(const std::string& name, const nlohmann::json& j) const {
  AtomicFile f(folder_ / name);
  f.stream() << j.dump(2) << '\n';
  f.commit();
}

}  // namespace bendlab
