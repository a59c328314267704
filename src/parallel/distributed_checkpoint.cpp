#include "bendlab/parallel/distributed_checkpoint.hpp"

#include <fmt/format.h>

#include <fstream>
#include <string>
#include <vector>

#include "bendlab/flow/lbm/checkpoint.hpp"

namespace bendlab::parallel {

namespace {

// Throws the first failing rank's message on every rank (empty `mine`: this rank succeeded).
void agree(MPI_Comm comm, const std::string& mine) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  int failed = mine.empty() ? -1 : rank, first = -1;
  MPI_Allreduce(&failed, &first, 1, MPI_INT, MPI_MAX, comm);
  if (first < 0) return;
  int len = static_cast<int>(mine.size());
  MPI_Bcast(&len, 1, MPI_INT, first, comm);
  std::string message = mine;
  message.resize(static_cast<std::size_t>(len));
  MPI_Bcast(message.data(), len, MPI_CHAR, first, comm);
  throw Error(rank == first ? message : fmt::format("rank {}: {}", first, message));
}

// File offset (bytes) of population q of global node (0, j, k).
MPI_Offset offset(const lbm::LatticeConfig& g, int q, int j, int k) {
  const std::size_t n = static_cast<std::size_t>(g.nx) * g.ny * g.nz;
  return static_cast<MPI_Offset>(lbm::kCheckpointHeaderBytes +
                                 sizeof(double) * (q * n + static_cast<std::size_t>(g.nx) * (j + static_cast<std::size_t>(g.ny) * k)));
}

}  // namespace

void write_checkpoint(const DistributedLattice& lattice, const std::filesystem::path& path) {
  const MPI_Comm comm = lattice.comm();
  const SlabDecomposition& s = lattice.slab();
  const lbm::LatticeConfig& g = lattice.config();
  std::filesystem::path temp = path;
  temp += ".tmp";
  std::string error;
  if (s.rank == 0) {
    std::error_code ec;
    std::filesystem::remove(temp, ec);  // a stale one of an interrupted run
  }
  MPI_Barrier(comm);  // the folder exists (rank 0 made it) and no stale file is left
  MPI_File file;
  if (MPI_File_open(comm, temp.c_str(), MPI_MODE_CREATE | MPI_MODE_WRONLY, MPI_INFO_NULL, &file) != MPI_SUCCESS) {
    agree(comm, fmt::format("cannot create LBM checkpoint {}", temp.string()));
  }
  agree(comm, "");
  const std::size_t n = lattice.local().slot_stride();
  const std::size_t layer = static_cast<std::size_t>(g.nx) * s.count;
  const std::size_t nl = static_cast<std::size_t>(s.count) + 2;
  const double* f = lattice.local().raw_data();
  bool ok = true;
  if (s.rank == 0) {
    const std::string header = lbm::checkpoint_header(g, lattice.step_count());
    ok = MPI_File_write_at(file, 0, header.data(), static_cast<int>(header.size()), MPI_BYTE, MPI_STATUS_IGNORE) ==
         MPI_SUCCESS;
  }
  for (int q = 0; q < lbm::kQ && ok; ++q)
    for (int k = 0; k < g.nz && ok; ++k) {
      const double* src = f + q * n + static_cast<std::size_t>(g.nx) * (1 + nl * k);
      ok = MPI_File_write_at(file, offset(g, q, s.begin, k), src, static_cast<int>(layer), MPI_DOUBLE,
                             MPI_STATUS_IGNORE) == MPI_SUCCESS;
    }
  ok = MPI_File_sync(file) == MPI_SUCCESS && ok;
  ok = MPI_File_close(&file) == MPI_SUCCESS && ok;
  if (!ok) error = fmt::format("cannot write LBM checkpoint {}", temp.string());
  try {
    agree(comm, error);
  } catch (const Error&) {
    if (s.rank == 0) {
      std::error_code ec;
      std::filesystem::remove(temp, ec);
    }
    throw;
  }
  if (s.rank == 0) {
    std::error_code ec;
    std::filesystem::rename(temp, path, ec);
    if (ec) error = fmt::format("cannot rename {} onto {}: {}", temp.string(), path.string(), ec.message());
  }
  agree(comm, error);
}

void read_checkpoint(DistributedLattice& lattice, const std::filesystem::path& path) {
  const SlabDecomposition& s = lattice.slab();
  const lbm::LatticeConfig& g = lattice.config();
  const std::size_t layer = static_cast<std::size_t>(g.nx) * s.count;
  std::vector<double> owned;
  std::int64_t step = 0;
  std::string error;
  try {
    step = lbm::check_checkpoint_header(g, path);
    std::ifstream in(path, std::ios::binary);
    owned.resize(lbm::kQ * layer * g.nz);
    double* dst = owned.data();
    for (int q = 0; q < lbm::kQ && in; ++q)
      for (int k = 0; k < g.nz && in; ++k, dst += layer) {
        in.seekg(static_cast<std::streamoff>(offset(g, q, s.begin, k)));
        in.read(reinterpret_cast<char*>(dst), static_cast<std::streamsize>(layer * sizeof(double)));
      }
    if (!in) throw Error(fmt::format("LBM checkpoint {} could not be read to the end", path.string()));
  } catch (const Error& e) {
    error = e.what();
  }
  agree(lattice.comm(), error);
  lattice.restore_owned(owned, step);
}

}  // namespace bendlab::parallel
