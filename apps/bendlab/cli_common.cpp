#include "cli_common.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "bendlab/core/output_folder.hpp"

namespace bendlab::cli {

std::string extension_of(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext;
}

void require_extension(const std::string& option, const std::filesystem::path& path,
                       const std::vector<std::string>& allowed) {
  const std::string ext = extension_of(path);
  if (std::find(allowed.begin(), allowed.end(), ext) == allowed.end())
    throw Error(fmt::format("{} '{}': the extension must be one of {}", option, path.string(), fmt::join(allowed, ", ")));
}

void require_writable_parent(const std::string& option, const std::filesystem::path& path) {
  const auto parent = parent_folder(path);
  if (!std::filesystem::is_directory(parent))
    throw Error(fmt::format("{} '{}': folder '{}' does not exist", option, path.string(), parent.string()));
}

std::unique_ptr<AnalyticSurface> surface_from_options(const std::string& shape, double radius,
                                                      const std::vector<double>& axes) {
  require_positive("--radius", radius);
  if (!axes.empty() && axes.size() != 2) throw Error("--axes takes two numbers: a,c");
  for (double a : axes) require_positive("--axes", a);
  return make_surface(shape, radius, axes);
}

}  // namespace bendlab::cli
