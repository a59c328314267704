#pragma once
// The folder an output path names, as a user types it: `--out r/` is the folder r, made in the
// current folder, as `--out r` is. std::filesystem reads "r/" as r with an empty file name, whose
// parent_path() is "r" itself: a check of that parent would refuse every new folder given with a
// trailing slash.
#include <filesystem>

namespace bendlab {

/// `path` without its trailing separators ("r/" is "r", "a/b//" is "a/b"; "/" stays "/").
std::filesystem::path without_trailing_separators(const std::filesystem::path& path);

/// The folder that must exist for `path` to be made in it: the parent of
/// without_trailing_separators(path), or "." for a bare name ("r", "r/").
std::filesystem::path parent_folder(const std::filesystem::path& path);

}  // namespace bendlab
