#pragma once
// Argument checks and small pieces shared by the subcommands. Every check throws bendlab::Error
// with a one-line message naming the option, before any work starts.
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "bendlab/surfaces/analytic_surface.hpp"

namespace bendlab::cli {

/// Throws unless value is finite and > 0 (or >= 0 with allow_zero).
void require_positive(const std::string& option, double value, bool allow_zero = false);
/// Lower-case extension of path, with the dot (".vtp").
std::string extension_of(const std::filesystem::path& path);
/// Throws unless the extension of path is one of `allowed`.
void require_extension(const std::string& option, const std::filesystem::path& path,
                       const std::vector<std::string>& allowed);
/// Throws unless the folder that will hold path exists.
void require_writable_parent(const std::string& option, const std::filesystem::path& path);
/// The analytic surface of --shape with --radius and --axes a,c.
std::unique_ptr<AnalyticSurface> surface_from_options(const std::string& shape, double radius,
                                                      const std::vector<double>& axes);

}  // namespace bendlab::cli

namespace bendlab::cli {

/// The folder of the running executable (from /proc/self/exe), empty if unknown.
std::filesystem::path executable_folder();
/// Runs `argv[0]` with the arguments argv (no shell) and waits; returns its exit status, or -1 if
/// it could not be started or did not exit normally.
int run_program(const std::vector<std::string>& argv);

}  // namespace bendlab::cli
