#include "bendlab/core/atomic_file.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include "bendlab/core/types.hpp"

namespace bendlab {

AtomicFile::AtomicFile(std::filesystem::path target, bool binary) : target_(std::move(target)) {
  temp_ = target_;
  temp_ += fmt::format(".tmp{}", static_cast<long>(::getpid()));
  out_.open(temp_, binary ? std::ios::out | std::ios::binary | std::ios::trunc : std::ios::out | std::ios::trunc);
  if (!out_) throw Error(fmt::format("cannot write '{}'", target_.string()));
  out_.precision(17);
}

AtomicFile::~AtomicFile() {
  if (!committed_) {
    out_.close();
    std::error_code ec;
    std::filesystem::remove(temp_, ec);
  }
}

void AtomicFile::commit() {
  out_.flush();
  if (!out_) throw Error(fmt::format("error while writing '{}'", target_.string()));
  out_.close();
  std::error_code ec;
  std::filesystem::rename(temp_, target_, ec);
  if (ec) throw Error(fmt::format("cannot write '{}': {}", target_.string(), ec.message()));
  committed_ = true;
}

}  // namespace bendlab
