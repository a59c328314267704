#pragma once
// Reading whole input files (meshes, checkpoints, time series) safely.
//
// Only regular files are read: a FIFO, a device, a socket or a folder is refused at once with a
// message naming it (opening a FIFO for reading would wait for a writer forever). Every failure
// gives the operating system's reason ("Permission denied", "No such file or directory").
#include <filesystem>
#include <string>

namespace bendlab {

/// The whole content of the regular file at path. Throws bendlab::Error naming the file and the
/// reason. `what` names the kind of file in messages ("mesh", "checkpoint"); empty for none.
std::string read_regular_file(const std::filesystem::path& path, const std::string& what = "");

/// Throws bendlab::Error unless path names an existing regular file (following symbolic links).
void require_regular_file(const std::filesystem::path& path, const std::string& what = "");

}  // namespace bendlab
