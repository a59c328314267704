#pragma once
// Argument checks and small pieces shared by the subcommands. Every check throws bendlab::Error
// with a one-line message naming the option, before any work starts.
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "bendlab/core/finite_check.hpp"
#include "bendlab/surfaces/analytic_surface.hpp"

namespace bendlab::cli {

using bendlab::require_positive;  // core/finite_check.hpp
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
