#pragma once
// Helper programs (the plotting scripts) started without a shell, and found at run time.
//
// Nothing here builds a command string: the program and its arguments travel as an argument
// vector to posix_spawn, so a file name with quotes, spaces or `;` is just a file name.
#include <filesystem>
#include <string>
#include <vector>

namespace bendlab {

/// Runs argv[0] (an absolute or relative path, not searched on PATH) with the arguments argv[1..],
/// waits for it and returns its exit status (128 + signal number if a signal ended it). Throws
/// bendlab::Error, with the operating system's reason, when the program cannot be started.
int run_helper_program(const std::vector<std::string>& argv);

/// The folder of the running executable (from /proc/self/exe), or empty where that is unknown.
std::filesystem::path executable_folder();

/// Finds the helper script `name` (e.g. "plot_shear.py"):
///   1. `explicit_path` when it is not empty (returned as given, whether it exists or not, so that
///      the caller can name it in an error);
///   2. <prefix>/share/bendlab/scripts/<name> for an installed executable in <prefix>/bin;
///   3. scripts/<name> in the executable's folder or up to four folders above it (a build tree
///      inside the source tree: build/release/bendlab -> scripts/);
///   4. scripts/<name> in the current folder or above it.
/// Returns an empty path when none exists.
std::filesystem::path find_helper_script(const std::string& name, const std::filesystem::path& explicit_path = {});

}  // namespace bendlab
