#include "bendlab/flow/lbm/checkpoint.hpp"

#include <fmt/format.h>

#include <cstring>
#include <fstream>

#include "bendlab/core/atomic_file.hpp"

namespace bendlab::lbm {

namespace {

constexpr char kMagic[8] = {'B', 'L', 'L', 'B', 'M', 'C', 'K', '\0'};
constexpr std::uint32_t kVersion = 1;

#pragma pack(push, 1)
struct Header {
  char magic[8];
  std::uint32_t version, q;
  std::int32_t nx, ny, nz, walls;
  double tau, wall_velocity;
  std::int64_t step;
  std::uint64_t count;
};
#pragma pack(pop)

static_assert(sizeof(Header) == kCheckpointHeaderBytes);

}  // namespace

std::string checkpoint_header(const LatticeConfig& c, std::int64_t step) {
  Header h{};
  std::memcpy(h.magic, kMagic, sizeof kMagic);
  h.version = kVersion;
  h.q = kQ;
  h.nx = c.nx;
  h.ny = c.ny;
  h.nz = c.nz;
  h.walls = c.walls ? 1 : 0;
  h.tau = c.tau;
  h.wall_velocity = c.wall_velocity;
  h.step = step;
  h.count = static_cast<std::uint64_t>(kQ) * c.nx * c.ny * c.nz;
  return std::string(reinterpret_cast<const char*>(&h), sizeof h);
}

std::int64_t check_checkpoint_header(const LatticeConfig& c, const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(fmt::format("cannot open LBM checkpoint {}", path.string()));
  const std::string name = path.string();
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  if (ec || size < sizeof(Header)) throw Error(fmt::format("LBM checkpoint {} is too short for its header", name));
  Header h{};
  in.read(reinterpret_cast<char*>(&h), sizeof h);
  if (!in || std::memcmp(h.magic, kMagic, sizeof kMagic) != 0) throw Error(fmt::format("{} is not an LBM checkpoint (bad magic)", name));
  if (h.version != kVersion) throw Error(fmt::format("LBM checkpoint {} has version {}, this build reads {}", name, h.version, kVersion));
  if (h.q != static_cast<std::uint32_t>(kQ) || h.nx != c.nx || h.ny != c.ny || h.nz != c.nz) {
    throw Error(fmt::format("LBM checkpoint {} is for a D3Q{} {} x {} x {} lattice, not D3Q{} {} x {} x {}", name, h.q, h.nx, h.ny, h.nz, kQ, c.nx, c.ny, c.nz));
  }
  if ((h.walls != 0) != c.walls || h.tau != c.tau || h.wall_velocity != c.wall_velocity) {
    throw Error(fmt::format("LBM checkpoint {} (walls {}, tau {}, wall velocity {}) does not match the lattice (walls {}, tau {}, wall velocity {})",
                            name, h.walls != 0, h.tau, h.wall_velocity, c.walls, c.tau, c.wall_velocity));
  }
  const std::uint64_t count = static_cast<std::uint64_t>(kQ) * c.nx * c.ny * c.nz;
  if (h.count != count || size != sizeof(Header) + count * sizeof(double)) {
    throw Error(fmt::format("LBM checkpoint {} has {} bytes, expected {}", name, size, sizeof(Header) + count * sizeof(double)));
  }
  if (h.step < 0) throw Error(fmt::format("LBM checkpoint {} has a negative step count {}", name, h.step));
  return h.step;
}

void write_checkpoint(const Lattice& lattice, const std::filesystem::path& path) {
  const std::string header = checkpoint_header(lattice.config(), lattice.step_count());
  AtomicFile out(path, true);
  out.stream().write(header.data(), static_cast<std::streamsize>(header.size()));
  // Slot by slot from the store (the packed layout of raw_populations() without its copy, which at
  // 128 x 128 x 256 nodes would be another 600 MB each time a checkpoint is written).
  const auto slot_bytes = static_cast<std::streamsize>(lattice.num_nodes() * sizeof(double));
  for (int q = 0; q < kQ; ++q) {
    const double* slot = lattice.raw_data() + static_cast<std::size_t>(q) * lattice.slot_stride();
    out.stream().write(reinterpret_cast<const char*>(slot), slot_bytes);
  }
  out.commit();
}

void read_checkpoint(Lattice& lattice, const std::filesystem::path& path) {
  const std::int64_t step = check_checkpoint_header(lattice.config(), path);
  const std::string name = path.string();
  std::ifstream in(path, std::ios::binary);
  in.seekg(static_cast<std::streamoff>(kCheckpointHeaderBytes));
  std::vector<double> f(kQ * lattice.num_nodes());
  in.read(reinterpret_cast<char*>(f.data()), static_cast<std::streamsize>(f.size() * sizeof(double)));
  if (!in) throw Error(fmt::format("LBM checkpoint {} could not be read to the end", name));
  lattice.restore_raw(f, step);
}

}  // namespace bendlab::lbm
