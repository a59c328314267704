#include "bendlab/core/output_folder.hpp"

#include <string>

namespace bendlab {

std::filesystem::path without_trailing_separators(const std::filesystem::path& path) {
  std::string s = path.string();
  while (s.size() > 1 && s.back() == '/') s.pop_back();
  return s;
}

std::filesystem::path parent_folder(const std::filesystem::path& path) {
  const std::filesystem::path p = without_trailing_separators(path);
  return p.has_parent_path() ? p.parent_path() : std::filesystem::path(".");
}

}  // namespace bendlab
