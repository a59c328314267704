#include "bendlab/core/atomic_file.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "bendlab/core/types.hpp"

namespace bendlab {

namespace {
// mkstemp's template suffix, and the characters glibc's mkstemp replaces it with.
constexpr char kTempTemplate[] = "XXXXXX";
constexpr std::size_t kTempSuffixLength = sizeof(kTempTemplate) - 1;
bool is_temp_suffix_char(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9');
}
}  // namespace

std::string atomic_temp_prefix(const std::filesystem::path& target) { return target.filename().string() + ".tmp"; }

std::optional<std::string> atomic_temp_target(const std::string& name) {
  static const std::string infix = ".tmp";
  if (name.size() <= infix.size() + kTempSuffixLength) return std::nullopt;  // an empty target name too
  const std::size_t at = name.size() - kTempSuffixLength - infix.size();
  if (name.compare(at, infix.size(), infix) != 0) return std::nullopt;
  for (std::size_t k = name.size() - kTempSuffixLength; k < name.size(); ++k)
    if (!is_temp_suffix_char(name[k])) return std::nullopt;
  return name.substr(0, at);
}

AtomicFile::AtomicFile(std::filesystem::path target, bool binary) : target_(std::move(target)), out_(nullptr) {
  std::filesystem::path pattern = target_;
  pattern.replace_filename(atomic_temp_prefix(target_) + kTempTemplate);
  const std::string pattern_text = pattern.string();
  std::vector<char> name(pattern_text.begin(), pattern_text.end());
  name.push_back('\0');
  const int fd = ::mkostemp(name.data(), O_CLOEXEC);
  if (fd < 0) throw Error(fmt::format("cannot write '{}': {}", target_.string(), std::strerror(errno)));
  temp_ = name.data();
  // mkstemp makes the file 0600; an output gets the permissions a plain open() would give it.
  const mode_t mask = ::umask(0);
  ::umask(mask);
  (void)::fchmod(fd, 0666 & ~mask);
  // The buffer owns the descriptor from here on and closes it.
  buffer_ = std::make_unique<__gnu_cxx::stdio_filebuf<char>>(
      fd, binary ? std::ios::out | std::ios::binary : std::ios::out, static_cast<std::size_t>(BUFSIZ));
  out_.rdbuf(buffer_.get());
  out_.precision(17);
}

AtomicFile::~AtomicFile() {
  if (!committed_) {
    out_.rdbuf(nullptr);
    buffer_.reset();
    std::error_code ec;
    std::filesystem::remove(temp_, ec);
  }
}

void AtomicFile::commit() {
  // A write past the file size limit (ulimit -f) fails with EFBIG once SIGXFSZ is ignored (the
  // command line does so): it lands here as a write error, and the destructor removes the file.
  out_.flush();
  if (!out_ || buffer_->close() == nullptr)
    throw Error(fmt::format("error while writing '{}'", target_.string()));
  std::error_code ec;
  std::filesystem::rename(temp_, target_, ec);
  if (ec) throw Error(fmt::format("cannot write '{}': {}", target_.string(), ec.message()));
  committed_ = true;
}

}  // namespace bendlab
