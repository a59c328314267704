#include "cli_common.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace bendlab::cli {

void require_positive(const std::string& option, double value, bool allow_zero) {
  if (!std::isfinite(value) || value < 0 || (!allow_zero && value == 0))
    throw Error(fmt::format("{} must be a finite number {} 0, got {}", option, allow_zero ? ">=" : ">", value));
}

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
  const auto parent = path.has_parent_path() ? path.parent_path() : std::filesystem::path(".");
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

#include <spawn.h>
#include <cerrno>
#include <sys/wait.h>

extern char** environ;

namespace bendlab::cli {

std::filesystem::path executable_folder() {
  std::error_code ec;
  const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  return ec ? std::filesystem::path() : exe.parent_path();
}

int run_program(const std::vector<std::string>& argv) {
  if (argv.empty()) return -1;
  std::vector<char*> args;
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  pid_t pid = 0;
  if (posix_spawn(&pid, args[0], nullptr, nullptr, args.data(), environ) != 0) return -1;
  int status = 0;
  while (waitpid(pid, &status, 0) < 0)
    if (errno != EINTR) return -1;
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

}  // namespace bendlab::cli
