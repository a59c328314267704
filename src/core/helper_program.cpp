#include "bendlab/core/helper_program.hpp"

#include <fmt/format.h>
#include <spawn.h>
#include <sys/wait.h>

#include <cerrno>
#include <cstring>

#include "bendlab/core/types.hpp"

extern char** environ;

namespace bendlab {

namespace fs = std::filesystem;

int run_helper_program(const std::vector<std::string>& argv) {
  if (argv.empty()) throw Error("run_helper_program: no program given");
  std::vector<char*> args;
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  pid_t pid = 0;
  const int rc = ::posix_spawn(&pid, argv[0].c_str(), nullptr, nullptr, args.data(), environ);
  if (rc != 0) throw Error(fmt::format("cannot start '{}': {}", argv[0], std::strerror(rc)));
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) throw Error(fmt::format("waiting for '{}': {}", argv[0], std::strerror(errno)));
  }
  if (WIFEXITED(status)) return WEXITSTATUS(status);
  if (WIFSIGNALED(status)) return 128 + WTERMSIG(status);
  return -1;
}

fs::path executable_folder() {
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  return ec ? fs::path() : exe.parent_path();
}

fs::path find_helper_script(const std::string& name, const fs::path& explicit_path) {
  if (!explicit_path.empty()) return explicit_path;
  std::error_code ec;
  auto is_file = [&](const fs::path& p) { return fs::is_regular_file(p, ec); };
  const fs::path exe_dir = executable_folder();
  if (!exe_dir.empty()) {
    if (const fs::path p = exe_dir.parent_path() / "share" / "bendlab" / "scripts" / name; is_file(p)) return p;
    fs::path dir = exe_dir;
    for (int up = 0; up < 5 && !dir.empty(); ++up, dir = dir.parent_path()) {
      if (const fs::path p = dir / "scripts" / name; is_file(p)) return p;
      if (dir == dir.parent_path()) break;
    }
  }
  fs::path dir = fs::current_path(ec);
  for (int up = 0; up < 5 && !ec && !dir.empty(); ++up, dir = dir.parent_path()) {
    if (const fs::path p = dir / "scripts" / name; is_file(p)) return p;
    if (dir == dir.parent_path()) break;
  }
  return {};
}

}  // namespace bendlab
