#pragma once
// The command line as a user meets it (tests/cli): bendlab started with an argument vector
// (posix_spawn, no shell), its stdout and stderr redirected to files, so that any byte a user may
// put in a file name reaches it unchanged; exit codes, one-line errors, files whole or absent.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

extern char** environ;

namespace bendlab_cli_test {

namespace fs = std::filesystem;

struct CliRun {
  int status;
  std::string out, err;
};

class Cli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir = fs::temp_directory_path() / ("bendlab_cli_" + std::to_string(::getpid()) + "_" +
                                       ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir);
    fs::create_directories(dir);
  }
  void TearDown() override { fs::remove_all(dir); }

  /// Runs bendlab with exactly these arguments; stdout and stderr go to dir/stdout.txt and
  /// dir/stderr.txt. The status is the exit code, or 128 + the signal that ended it.
  CliRun run(const std::vector<std::string>& args) {
    const fs::path o = dir / "stdout.txt", e = dir / "stderr.txt";
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, o.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, e.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    std::vector<std::string> words{BENDLAB_CLI_PATH};
    words.insert(words.end(), args.begin(), args.end());
    std::vector<char*> argv;
    for (std::string& w : words) argv.push_back(w.data());
    argv.push_back(nullptr);
    pid_t pid = 0;
    const int rc = posix_spawn(&pid, BENDLAB_CLI_PATH, &actions, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    if (rc != 0) {
      ADD_FAILURE() << "cannot start " << BENDLAB_CLI_PATH << ": " << std::strerror(rc);
      return {-1, "", ""};
    }
    int status = 0;
    while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
    const int code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    return {code, slurp(o), slurp(e)};
  }
  /// The same with the arguments given as words separated by single spaces (for the many tests
  /// whose arguments hold no space; a path with spaces needs the vector form above).
  CliRun run(const std::string& args) {
    std::vector<std::string> words;
    std::istringstream in(args);
    for (std::string w; std::getline(in, w, ' ');)
      if (!w.empty()) words.push_back(w);
    return run(words);
  }
  static std::string slurp(const fs::path& p) {
    std::ifstream in(p);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
  }
  void write(const fs::path& p, const std::string& text) { std::ofstream(p) << text; }
  // A usage or input error: non-zero exit, exactly one line on stderr naming the problem, and no
  // output file left behind.
  void expect_refused(const CliRun& r, const std::string& problem, const fs::path& out) {
    EXPECT_NE(r.status, 0);
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_NE(r.err.find(problem), std::string::npos) << "stderr: " << r.err;
    EXPECT_FALSE(fs::exists(out)) << out;
    for (const auto& entry : fs::directory_iterator(dir))
      EXPECT_EQ(entry.path().filename().string().find(".tmp"), std::string::npos) << entry.path();
  }
  // Two run folders hold the same files, byte for byte: every file but timing.json (the clock), and
  // checkpoint.json but its "wall_seconds" (the clock). Snapshots, fluid slices, side files and
  // the checkpoint's list of snapshots included.
  static void expect_same_run_files(const fs::path& a, const fs::path& b) {
    auto names = [](const fs::path& folder) {
      std::vector<std::string> n;
      for (const auto& entry : fs::directory_iterator(folder)) n.push_back(entry.path().filename().string());
      std::sort(n.begin(), n.end());
      return n;
    };
    const std::vector<std::string> na = names(a);
    EXPECT_EQ(na, names(b));
    for (const std::string& name : na) {
      if (name == "timing.json") continue;
      if (name == "checkpoint.json") {
        nlohmann::json ca = nlohmann::json::parse(slurp(a / name)), cb = nlohmann::json::parse(slurp(b / name));
        ca.erase("wall_seconds");
        cb.erase("wall_seconds");
        EXPECT_EQ(ca, cb) << name;
        continue;
      }
      EXPECT_TRUE(slurp(a / name) == slurp(b / name)) << name << " differs between " << a << " and " << b;
    }
  }
  fs::path dir;
};

}  // namespace bendlab_cli_test
