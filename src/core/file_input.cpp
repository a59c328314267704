#include "bendlab/core/file_input.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "bendlab/core/types.hpp"

namespace bendlab {

namespace {

std::string subject(const std::filesystem::path& path, const std::string& what) {
  return what.empty() ? fmt::format("'{}'", path.string()) : fmt::format("{} '{}'", what, path.string());
}

const char* kind_of(mode_t mode) {
  if (S_ISDIR(mode)) return "a folder";
  if (S_ISFIFO(mode)) return "a FIFO (named pipe)";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a regular file";
}

// Closes the descriptor on every path out.
struct Descriptor {
  int fd = -1;
  ~Descriptor() {
    if (fd >= 0) ::close(fd);
  }
};

}  // namespace

void require_regular_file(const std::filesystem::path& path, const std::string& what) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0)
    throw Error(fmt::format("cannot read {}: {}", subject(path, what), std::strerror(errno)));
  if (!S_ISREG(st.st_mode))
    throw Error(fmt::format("cannot read {}: it is {}, not a regular file", subject(path, what), kind_of(st.st_mode)));
}

std::string read_regular_file(const std::filesystem::path& path, const std::string& what) {
  require_regular_file(path, what);
  // O_NONBLOCK: if the path was swapped for a FIFO after the check, open() does not wait for a
  // writer; fstat below then refuses it.
  Descriptor d;
  d.fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (d.fd < 0) throw Error(fmt::format("cannot read {}: {}", subject(path, what), std::strerror(errno)));
  struct stat st {};
  if (::fstat(d.fd, &st) != 0 || !S_ISREG(st.st_mode))
    throw Error(fmt::format("cannot read {}: it is not a regular file", subject(path, what)));
  std::string bytes(static_cast<std::size_t>(st.st_size), '\0');
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::read(d.fd, bytes.data() + done, bytes.size() - done);
    if (n < 0) {
      if (errno == EINTR || errno == EAGAIN) continue;
      throw Error(fmt::format("cannot read {}: {} after {} of {} bytes", subject(path, what), std::strerror(errno), done,
                              bytes.size()));
    }
    if (n == 0) {  // the file shrank while being read
      bytes.resize(done);
      break;
    }
    done += static_cast<std::size_t>(n);
  }
  return bytes;
}

}  // namespace bendlab
