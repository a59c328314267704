#include "bendlab/parallel/distributed_lattice.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <string>

namespace bendlab::parallel {

namespace {

int comm_rank(MPI_Comm comm) {
  int r = 0;
  MPI_Comm_rank(comm, &r);
  return r;
}
int comm_size(MPI_Comm comm) {
  int n = 1;
  MPI_Comm_size(comm, &n);
  return n;
}

// The global cross-section seen from a subdomain: local y + shift = global y.
class ShiftedSection final : public lbm::SectionWalls {
 public:
  ShiftedSection(std::shared_ptr<const lbm::SectionWalls> global, double shift) : global_(std::move(global)), shift_(shift) {}
  bool solid(double y, double z) const override { return global_->solid(y + shift_, z); }
  double link_fraction(double y, double z, int cy, int cz) const override {
    return global_->link_fraction(y + shift_, z, cy, cz);
  }
  std::string describe() const override { return global_->describe(); }

 private:
  std::shared_ptr<const lbm::SectionWalls> global_;
  double shift_;
};

// Local y + y_shift(...) = global y of the same node (half-integers: exact).
double y_shift(const lbm::LatticeConfig& global, const SlabDecomposition& s) {
  return s.begin - 1 + 0.5 * (s.count + 2) - 0.5 * global.ny;
}

lbm::LatticeConfig local_config(lbm::LatticeConfig c, const SlabDecomposition& s) {
  const double shift = y_shift(c, s);
  c.ny = s.count + 2;
  c.ghost_y_layers = true;
  if (c.section) c.section = std::make_shared<ShiftedSection>(c.section, shift);
  return c;
}

enum Tag : int { kToUpper = 701, kToLower = 702 };

}  // namespace

DistributedLattice::DistributedLattice(const lbm::LatticeConfig& global, MPI_Comm comm)
    : global_(global),
      comm_(comm),
      slab_(SlabDecomposition::of(global.ny, comm_size(comm), comm_rank(comm))),
      local_(local_config(global, slab_)) {
  const std::size_t face = kFacePopulations * static_cast<std::size_t>(global.nx) * global.nz;
  send_lo_.resize(face);
  send_hi_.resize(face);
  recv_lo_.resize(face);
  recv_hi_.resize(face);
}

Vec3 DistributedLattice::position(int i, int j, int k) const {
  return {i + 0.5 - 0.5 * global_.nx, j + 0.5 - 0.5 * global_.ny, k + 0.5 - 0.5 * global_.nz};
}

void DistributedLattice::initialise(const std::function<Vec3(const Vec3&)>& velocity,
                                    const std::function<double(const Vec3&)>& density) {
  const double shift = y_shift(global_, slab_);
  auto to_global = [shift](Vec3 x) {
    x.y() += shift;
    return x;
  };
  local_.initialise([&](const Vec3& x) { return velocity(to_global(x)); },
                    density ? std::function<double(const Vec3&)>([&](const Vec3& x) { return density(to_global(x)); })
                            : nullptr);
}

void DistributedLattice::initialise_shear_flow() { local_.initialise_shear_flow(); }

void DistributedLattice::step() {
  const bool even = local_.step_count() % 2 == 0;
  local_.collide_stream_layers(1, slab_.count + 1);
  const double t0 = MPI_Wtime();
  exchange(even);
  halo_seconds_ += MPI_Wtime() - t0;
  // The section's interpolated bounce-back reads populations that stream in from the ghost
  // layers (after an even step, f*_q(x_f - c_q) sits in the ghost node x_f - c_q; after an odd
  // one the neighbour pushed it into x_f and the return brought it back), so it runs after the
  // exchange. It writes only owned nodes' slots that no neighbour reads (lattice.hpp).
  local_.correct_section_walls(1, slab_.count + 1);
}

void DistributedLattice::exchange(bool fill) {
  const int nx = global_.nx, nz = global_.nz, nl = slab_.count + 2;
  const std::size_t n = local_.slot_stride();
  double* f = local_.raw_data();
  const int lo = (slab_.rank + slab_.ranks - 1) % slab_.ranks, hi = (slab_.rank + 1) % slab_.ranks;
  auto at = [&](int q, int jl, int k) { return f + q * n + static_cast<std::size_t>(nx) * (jl + static_cast<std::size_t>(nl) * k); };
  auto pack = [&](const int* slots, int jl, std::vector<double>& buf) {
    double* b = buf.data();
    for (int s = 0; s < kFacePopulations; ++s)
      for (int k = 0; k < nz; ++k, b += nx) std::copy_n(at(slots[s], jl, k), nx, b);
  };
  // `masked`: a slot whose source node x - c lies in a wall is written by the owner's own
  // bounce-back, not by the neighbour: keep it. So is every slot of a solid row of the section,
  // which the serial lattice never writes (its checkpoint holds the state at rest there), and a
  // slot whose source row is solid (bounced back by the owner).
  auto unpack = [&](const int* slots, int jl, const std::vector<double>& buf, bool masked) {
    const double* b = buf.data();
    for (int s = 0; s < kFacePopulations; ++s) {
      const int q = slots[s];
      for (int k = 0; k < nz; ++k, b += nx) {
        const int ks = k - lbm::kCz[q];
        if (masked && global_.walls && (ks < 0 || ks >= nz)) continue;
        if (masked && global_.section &&
            (local_.solid_row(jl, k) || local_.solid_row(jl - lbm::kCy[q], (ks + nz) % nz)))
          continue;
        std::copy_n(b, nx, at(q, jl, k));
      }
    }
  };
  auto swap = [&](int to, int from, int tag, const std::vector<double>& out, std::vector<double>& in) {
    const int rc = MPI_Sendrecv(out.data(), static_cast<int>(out.size()), MPI_DOUBLE, to, tag, in.data(),
                                static_cast<int>(in.size()), MPI_DOUBLE, from, tag, comm_, MPI_STATUS_IGNORE);
    if (rc != MPI_SUCCESS) throw Error(fmt::format("LBM halo exchange failed on rank {} (MPI error {})", slab_.rank, rc));
    halo_doubles_ += static_cast<std::int64_t>(out.size());
  };
  const int top = slab_.count, bottom = 1, ghost_lo = 0, ghost_hi = slab_.count + 1;
  if (fill) {
    // After the in-place step, slot qbar of a node holds the post-collision f_q that streams to
    // x + c_q: c_y = +1 populations (lower-face slots) go up, c_y = -1 ones (upper-face slots) down.
    pack(kLowerFaceSlots, top, send_hi_);
    pack(kUpperFaceSlots, bottom, send_lo_);
    swap(hi, lo, kToUpper, send_hi_, recv_lo_);
    swap(lo, hi, kToLower, send_lo_, recv_hi_);
    unpack(kLowerFaceSlots, ghost_lo, recv_lo_, false);
    unpack(kUpperFaceSlots, ghost_hi, recv_hi_, false);
  } else {
    // After the streaming step, the ghost layers hold what the owned nodes wrote to x + c_q.
    pack(kLowerFaceSlots, ghost_lo, send_lo_);
    pack(kUpperFaceSlots, ghost_hi, send_hi_);
    swap(lo, hi, kToLower, send_lo_, recv_hi_);
    swap(hi, lo, kToUpper, send_hi_, recv_lo_);
    unpack(kLowerFaceSlots, top, recv_hi_, true);
    unpack(kUpperFaceSlots, bottom, recv_lo_, true);
  }
}

void DistributedLattice::restore_owned(const std::vector<double>& owned, std::int64_t step) {
  const int nx = global_.nx, nz = global_.nz, nl = slab_.count + 2;
  const std::size_t layer = static_cast<std::size_t>(nx) * slab_.count;
  if (owned.size() != lbm::kQ * layer * nz)
    throw Error(fmt::format("LBM subdomain state has {} populations, rank {} owns {}", owned.size(), slab_.rank,
                            lbm::kQ * layer * nz));
  std::vector<double> raw = local_.raw_populations();
  const std::size_t n = local_.num_nodes();
  const double* src = owned.data();
  for (int q = 0; q < lbm::kQ; ++q)
    for (int k = 0; k < nz; ++k, src += layer)
      std::copy_n(src, layer, raw.data() + q * n + static_cast<std::size_t>(nx) * (1 + static_cast<std::size_t>(nl) * k));
  local_.restore_raw(raw, step);
  if (step % 2 == 1) exchange(true);
}

void DistributedLattice::check_blow_up() const {
  // The first node in global index order with a non-finite or non-positive density, as
  // lbm::find_blow_up reports it.
  const lbm::LatticeConfig& g = global_;
  const SlabDecomposition& s = slab_;
  const lbm::Lattice& local = local_;
  long long first = std::numeric_limits<long long>::max();
  double rho_first = 0;
  for (int k = 0; k < g.nz && first == std::numeric_limits<long long>::max(); ++k)
    for (int j = s.begin; j < s.begin + s.count && first == std::numeric_limits<long long>::max(); ++j)
      for (int i = 0; i < g.nx; ++i) {
        const double rho = local.density(local_node(i, j, k));
        if (!std::isfinite(rho) || !(rho > 0)) {
          first = i + static_cast<long long>(g.nx) * (j + static_cast<long long>(g.ny) * k);
          rho_first = rho;
          break;
        }
      }
  long long global_first = 0;
  MPI_Allreduce(&first, &global_first, 1, MPI_LONG_LONG, MPI_MIN, comm_);
  if (global_first == std::numeric_limits<long long>::max()) return;
  const int i = static_cast<int>(global_first % g.nx);
  const long long r = global_first / g.nx;
  const int j = static_cast<int>(r % g.ny), k = static_cast<int>(r / g.ny);
  MPI_Bcast(&rho_first, 1, MPI_DOUBLE, s.owner(j), comm_);
  const Vec3 x = position(i, j, k);
  throw Error(fmt::format("LBM blew up at step {}: density {} at node ({}, {}, {}) (position {:.3g}, {:.3g}, {:.3g})",
                          step_count(), rho_first, i, j, k, x.x(), x.y(), x.z()));
}

double DistributedLattice::total_mass() const {
  double m = 0;
  for (int k = 0; k < global_.nz; ++k)
    for (int j = 1; j <= slab_.count; ++j)
      if (!local_.solid_row(j, k))  // fluid nodes only, as Lattice::total_mass
        for (int i = 0; i < global_.nx; ++i) m += local_.density(local_.index(i, j, k));
  double total = 0;
  MPI_Allreduce(&m, &total, 1, MPI_DOUBLE, MPI_SUM, comm_);
  return total;
}

}  // namespace bendlab::parallel
