#include "bendlab/parallel/mpi_suspension.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include <omp.h>

namespace bendlab::parallel {

namespace {

constexpr std::size_t kNotHere = std::numeric_limits<std::size_t>::max();  // a node in another rank's layers

// Sends send[r] to every rank r and returns what each rank sent here, with the counts exchanged
// first (collective).
std::vector<double> all_to_all(const std::vector<std::vector<double>>& send, MPI_Comm comm, std::vector<int>& from_rank) {
  const int ranks = static_cast<int>(send.size());
  std::vector<int> send_counts(ranks), recv_counts(ranks), send_displs(ranks + 1, 0), recv_displs(ranks + 1, 0);
  for (int r = 0; r < ranks; ++r) send_counts[r] = static_cast<int>(send[r].size());
  MPI_Alltoall(send_counts.data(), 1, MPI_INT, recv_counts.data(), 1, MPI_INT, comm);
  for (int r = 0; r < ranks; ++r) {
    send_displs[r + 1] = send_displs[r] + send_counts[r];
    recv_displs[r + 1] = recv_displs[r] + recv_counts[r];
  }
  std::vector<double> out(static_cast<std::size_t>(send_displs[ranks])), in(static_cast<std::size_t>(recv_displs[ranks]));
  for (int r = 0; r < ranks; ++r) std::copy(send[r].begin(), send[r].end(), out.begin() + send_displs[r]);
  MPI_Alltoallv(out.data(), send_counts.data(), send_displs.data(), MPI_DOUBLE, in.data(), recv_counts.data(),
                recv_displs.data(), MPI_DOUBLE, comm);
  from_rank.assign(in.size(), 0);
  for (int r = 0; r < ranks; ++r) std::fill(from_rank.begin() + recv_displs[r], from_rank.begin() + recv_displs[r + 1], r);
  return in;
}

}  // namespace

MpiSuspension::MpiSuspension(lbm::SuspensionOptions options, MPI_Comm comm)
    : options_(lbm::checked_suspension_options(std::move(options))), fluid_(options_.lattice, comm) {
  // A cell that moves to another rank would leave its held membrane forces behind.
  if (options_.membrane_every != 1)
    throw Error(fmt::format("membrane forces every {} steps: the MPI suspension computes them every step; run with one process", options_.membrane_every));
}

int MpiSuspension::add_cell(std::shared_ptr<const MembraneModel> membrane, const Points& X) {
  const int c = num_cells();
  const Eigen::Index first = X_.rows();
  lbm::append_cell_rows(membrane.get(), X, X_);
  cells_.push_back(Cell{std::move(membrane), first});
  cell_of_.resize(X_.rows(), c);
  F_.setZero(X_.rows(), 3);
  U_.setZero(X_.rows(), 3);
  restore(X_);
  return c;
}

void MpiSuspension::restore(const Points& X) {
  if (X.rows() != X_.rows() || X.cols() != 3 || !X.allFinite())
    throw Error(fmt::format("suspension: {} restored positions for {} vertices", X.rows(), X_.rows()));
  X_ = X;
  // Every rank holds every cell until the first step sends each to the ranks it reaches.
  held_.resize(cells_.size());
  owner_.resize(cells_.size());
  owned_.clear();
  for (int c = 0; c < num_cells(); ++c) {
    held_[c] = c;
    owner_[c] = owner_of_layer_at(centroid_y(c));
    if (owner_[c] == fluid_.slab().rank) owned_.push_back(c);
  }
  extent_y_ = extent_y(held_);
}

double MpiSuspension::centroid_y(int c) const { return X_.middleRows(first_row(c), rows(c)).col(1).mean(); }

int MpiSuspension::owner_of_layer_at(double y) const {
  const int ny = fluid_.config().ny;
  int j = static_cast<int>(std::floor(y + 0.5 * ny));
  j = options_.vessel.periodic(1) ? ((j % ny) + ny) % ny : std::clamp(j, 0, ny - 1);
  return fluid_.slab().owner(j);
}

double MpiSuspension::extent_y(const std::vector<int>& cells) const {
  double e = 0;
  for (int c : cells) {
    const auto y = X_.middleRows(first_row(c), rows(c)).col(1);
    const double mean = y.mean();
    e = std::max(e, std::max(y.maxCoeff() - mean, mean - y.minCoeff()));
  }
  return e;
}

std::vector<int> MpiSuspension::reach(int c) const {
  const int ny = fluid_.config().ny;
  const int m = static_cast<int>(std::ceil(lbm::ib_kernel_half_width(options_.kernel)));
  const auto y = X_.middleRows(first_row(c), rows(c)).col(1);
  const double lo_y = y.minCoeff(), hi_y = y.maxCoeff();
  // The stencils' layers; the layers that hold the centroid of a cell with a vertex within the
  // cutoff; one layer more on either side against rounding (a surplus ghost changes nothing).
  const bool contact = options_.cell_contact.max_force > 0 && cells_.size() > 1;
  const double R = contact ? options_.cell_contact.cutoff + extent_y_ : 0.0;
  const double half = 0.5 * ny;
  const long long lo = std::min<long long>(static_cast<long long>(std::floor(lo_y + half - 0.5)) - m + 1,
                                           static_cast<long long>(std::floor(lo_y - R + half))) - 1;
  const long long hi = std::max<long long>(static_cast<long long>(std::floor(hi_y + half - 0.5)) + m,
                                           static_cast<long long>(std::floor(hi_y + R + half))) + 1;
  const SlabDecomposition& s = fluid_.slab();
  std::vector<int> ranks;
  auto add_layers = [&](int a, int b) {  // 0 <= a <= b < ny
    for (int r = s.owner(a); r <= s.owner(b); ++r) ranks.push_back(r);
  };
  if (!options_.vessel.periodic(1)) {
    add_layers(static_cast<int>(std::clamp<long long>(lo, 0, ny - 1)), static_cast<int>(std::clamp<long long>(hi, 0, ny - 1)));
  } else if (hi - lo + 1 >= ny) {
    add_layers(0, ny - 1);
  } else {
    const int a = static_cast<int>(((lo % ny) + ny) % ny), b = static_cast<int>(((hi % ny) + ny) % ny);
    if (a <= b) {
      add_layers(a, b);
    } else {
      add_layers(0, b);
      add_layers(a, ny - 1);
    }
  }
  std::sort(ranks.begin(), ranks.end());
  ranks.erase(std::unique(ranks.begin(), ranks.end()), ranks.end());
  return ranks;
}

std::vector<int> MpiSuspension::exchange_rows(const std::vector<int>& cells, Points& M) {
  const int me = fluid_.slab().rank, ranks = fluid_.slab().ranks;
  std::vector<std::vector<double>> send(static_cast<std::size_t>(ranks));
  for (int c : cells) {
    for (int r : reach(c)) {
      if (r == me) continue;
      std::vector<double>& b = send[static_cast<std::size_t>(r)];
      b.push_back(static_cast<double>(c));
      for (Eigen::Index k = first_row(c); k < first_row(c) + rows(c); ++k) b.insert(b.end(), {M(k, 0), M(k, 1), M(k, 2)});
    }
  }
  std::vector<int> from;
  const std::vector<double> in = all_to_all(send, fluid_.comm(), from);
  std::vector<int> received;
  for (std::size_t at = 0; at < in.size();) {
    const int c = static_cast<int>(in[at++]);
    for (Eigen::Index k = first_row(c); k < first_row(c) + rows(c); ++k, at += 3) M.row(k) << in[at], in[at + 1], in[at + 2];
    received.push_back(c);
  }
  std::sort(received.begin(), received.end());
  return received;
}

void MpiSuspension::agree() {
  // MAX of (E, -rank of a failure): the largest extent and the lowest failing rank.
  const int me = fluid_.slab().rank;
  const double none = -std::numeric_limits<double>::max();
  double local[2] = {extent_y(owned_), failure_.empty() ? none : -static_cast<double>(me)}, global[2];
  MPI_Allreduce(local, global, 2, MPI_DOUBLE, MPI_MAX, fluid_.comm());
  extent_y_ = global[0];
  if (global[1] == none) return;
  const int root = static_cast<int>(-global[1]);
  int length = static_cast<int>(failure_.size());
  MPI_Bcast(&length, 1, MPI_INT, root, fluid_.comm());
  std::string message = me == root ? failure_ : std::string(static_cast<std::size_t>(length), ' ');
  MPI_Bcast(message.data(), length, MPI_CHAR, root, fluid_.comm());
  throw Error(message);
}

void MpiSuspension::fail(const std::string& what) {
  if (failure_.empty()) failure_ = what;
}

void MpiSuspension::step() {
  const std::int64_t n = steps() + 1;
  const int me = fluid_.slab().rank;
  failure_.clear();
  // a. Positions from the last step's owners to every rank their cells reach; then the owners of
  // this step, from the centroids.
  std::vector<int> kept;
  for (int c : owned_) {
    const std::vector<int> r = reach(c);
    if (std::binary_search(r.begin(), r.end(), me)) kept.push_back(c);
  }
  const std::vector<int> received = exchange_rows(owned_, X_);
  held_.clear();
  std::merge(kept.begin(), kept.end(), received.begin(), received.end(), std::back_inserter(held_));
  std::fill(owner_.begin(), owner_.end(), -1);
  owned_.clear();
  for (int c : held_) {
    owner_[c] = owner_of_layer_at(centroid_y(c));
    if (owner_[c] == me) owned_.push_back(c);
  }
  // b-c. The owners' forces, to the ranks that hold the cells.
  compute_forces(n);
  exchange_rows(owned_, F_);
  // d-g.
  spread_and_step(n);
  interpolate_and_move(n);
  agree();
}

void MpiSuspension::compute_forces(std::int64_t n) {
  // Membrane forces, a cell per thread, as LbmSuspension::step.
  const int threads = owned_.size() > 1 ? omp_get_max_threads() : 1;
  if (static_cast<int>(scratch_.size()) < threads) scratch_.resize(static_cast<std::size_t>(threads));
  const auto count = static_cast<std::ptrdiff_t>(owned_.size());
  std::vector<std::string> errors(owned_.size());
#pragma omp parallel for schedule(dynamic) num_threads(threads) if (threads > 1)
  for (std::ptrdiff_t o = 0; o < count; ++o) {
    const int c = owned_[static_cast<std::size_t>(o)];
    Scratch& s = scratch_[static_cast<std::size_t>(omp_get_thread_num())];
    try {
      s.x = X_.middleRows(first_row(c), rows(c));
      membrane(c).forces(s.x, s.f);
      F_.middleRows(first_row(c), rows(c)) = s.f;
    } catch (const Error& e) {
      errors[static_cast<std::size_t>(o)] = fmt::format("suspension step {}: cell {}: {}", n, c, e.what());
    }
  }
  for (const std::string& e : errors)
    if (!e.empty()) fail(e);
  if (options_.vertex_force != Vec3::Zero())
    for (int c : owned_) F_.middleRows(first_row(c), rows(c)).rowwise() += options_.vertex_force.transpose();
  // Contact and wall forces from the held cells' rows, in their order (contact.hpp: a vertex's
  // pairs are summed in row order, so the serial forces).
  const bool cell_contact = options_.cell_contact.max_force > 0 && cells_.size() > 1;
  const bool walls = options_.vessel.kind() != VesselKind::Box || fluid_.config().walls;
  const bool wall_contact = options_.wall_contact.max_force > 0 && walls;
  if (!cell_contact && !wall_contact) return;
  Eigen::Index total = 0;
  for (int c : held_) total += rows(c);
  held_x_.resize(total, 3);
  held_f_.resize(total, 3);
  held_cell_of_.resize(static_cast<std::size_t>(total));
  Eigen::Index at = 0;
  for (int c : held_) {
    held_x_.middleRows(at, rows(c)) = X_.middleRows(first_row(c), rows(c));
    held_f_.middleRows(at, rows(c)) = F_.middleRows(first_row(c), rows(c));  // a ghost's is not used
    std::fill_n(held_cell_of_.begin() + at, rows(c), c);
    at += rows(c);
  }
  if (cell_contact) contact_.add_cell_contact(options_.vessel, options_.cell_contact, held_x_, held_cell_of_, held_f_);
  if (wall_contact) add_wall_contact(options_.vessel, options_.wall_contact, held_x_, held_f_);
  at = 0;
  for (int c : held_) {
    if (owner_[c] == fluid_.slab().rank) F_.middleRows(first_row(c), rows(c)) = held_f_.middleRows(at, rows(c));
    at += rows(c);
  }
}

std::string MpiSuspension::make_stencil(Eigen::Index k, std::size_t at) {
  const lbm::LatticeConfig& g = fluid_.config();
  const SlabDecomposition& slab = fluid_.slab();
  lbm::IbStencil st;
  std::string error;
  try {
    st = lbm::ib_stencil({g.nx, g.ny, g.nz}, g.walls, row(X_, k), options_.kernel);
  } catch (const Error& e) {
    error = e.what();
    st.size = 0;
  }
  const auto nx = static_cast<std::size_t>(g.nx), ny = static_cast<std::size_t>(g.ny);
  for (int s = 0; s < per_row_; ++s, ++at) {
    entry_weight_[at] = s < st.size ? st.weight[s] : 0.0;
    if (entry_weight_[at] == 0.0) continue;
    const std::size_t node = st.node[s], line = node / nx;  // node = i + nx (j + ny k)
    const int i = static_cast<int>(node - nx * line), j = static_cast<int>(line % ny), kz = static_cast<int>(line / ny);
    entry_owner_[at] = slab.owner(j);
    if (slab.owns(j)) entry_local_[at] = fluid_.local_node(i, j, kz);
  }
  return error;
}

void MpiSuspension::spread_and_step(std::int64_t n) {
  // d. The stencils of every held row (on OpenMP threads), then the forces onto this rank's
  // layers, row after row in the order of the cells' indices: each node sums the serial terms in
  // the serial order. A stencil that cannot be made (a non-finite position, a support across a
  // wall) fails alike on every rank that holds the row, and is left with zero weights so that the
  // exchanges below stay matched.
  const int m = static_cast<int>(std::ceil(lbm::ib_kernel_half_width(options_.kernel)));
  per_row_ = 8 * m * m * m;  // (2 m)^3
  std::vector<Eigen::Index>& held_rows = held_rows_;
  held_rows.clear();
  for (int c : held_)
    for (Eigen::Index k = first_row(c); k < first_row(c) + rows(c); ++k) held_rows.push_back(k);
  const std::size_t entries = held_rows.size() * static_cast<std::size_t>(per_row_);
  entry_weight_.resize(entries);
  entry_owner_.resize(entries);
  entry_local_.assign(entries, kNotHere);
  const auto count = static_cast<std::ptrdiff_t>(held_rows.size());
  std::ptrdiff_t first_failure = count;
  std::string failure;
#pragma omp parallel for schedule(static) if (count >= 1024)
  for (std::ptrdiff_t r = 0; r < count; ++r) {
    const std::string error = make_stencil(held_rows[static_cast<std::size_t>(r)], static_cast<std::size_t>(r) * per_row_);
    if (!error.empty()) {
#pragma omp critical
      if (r < first_failure) first_failure = r, failure = error;
    }
  }
  if (first_failure < count) fail(fmt::format("suspension step {}: IB node {}: {}", n, held_rows[static_cast<std::size_t>(first_failure)], failure));
  lbm::Lattice& lat = fluid_.local();
  lat.clear_force();
  for (std::ptrdiff_t r = 0; r < count; ++r) {
    const Vec3 Fk = row(F_, held_rows[static_cast<std::size_t>(r)]);
    for (std::size_t e = static_cast<std::size_t>(r) * per_row_, end = e + per_row_; e < end; ++e)
      if (entry_weight_[e] != 0.0 && entry_local_[e] != kNotHere) lat.add_force(entry_local_[e], entry_weight_[e] * Fk);
  }
  // e.
  fluid_.step();
}

void MpiSuspension::compute_stencil_velocities() {
  // The velocity of every node of this rank's layers in some held stencil, once (a membrane with
  // about a vertex per dx visits each node about four times), in the order of the local nodes'
  // indices so that the population arrays are read front to back, as IbInterpolator does.
  const lbm::Lattice& lat = fluid_.local();
  const std::size_t n = lat.num_nodes();
  marks_.assign((n + 63) / 64, 0);
  for (std::size_t e = 0; e < entry_local_.size(); ++e) {
    const std::size_t node = entry_local_[e];
    if (entry_weight_[e] != 0.0 && node != kNotHere) marks_[node / 64] |= std::uint64_t{1} << (node % 64);
  }
  touched_.clear();
  for (std::size_t w = 0; w < marks_.size(); ++w)
    for (std::uint64_t bits = marks_[w]; bits != 0; bits &= bits - 1)
      touched_.push_back(64 * w + static_cast<std::size_t>(__builtin_ctzll(bits)));
  if (node_velocity_.size() != 3 * n) node_velocity_.assign(3 * n, 0.0);
  const auto touched = static_cast<std::ptrdiff_t>(touched_.size());
#pragma omp parallel for schedule(static) if (touched >= 4096)
  for (std::ptrdiff_t t = 0; t < touched; ++t) {
    const std::size_t node = touched_[static_cast<std::size_t>(t)];
    const Vec3 v = lat.velocity(node);
    node_velocity_[3 * node] = v.x(), node_velocity_[3 * node + 1] = v.y(), node_velocity_[3 * node + 2] = v.z();
  }
}

void MpiSuspension::interpolate_and_move(std::int64_t n) {
  // f. The velocities of the stencil nodes in this rank's layers that the other owners' vertices
  // need, in the order of their cells, rows and stencil entries; the owners read them in the same
  // order.
  const SlabDecomposition& slab = fluid_.slab();
  const int me = slab.rank;
  compute_stencil_velocities();
  const auto per_row = static_cast<std::size_t>(per_row_);
  std::vector<std::vector<double>> send(static_cast<std::size_t>(slab.ranks));
  std::size_t at = 0;  // the held row's first entry
  for (int c : held_) {
    const int o = owner_[c];
    if (o == me) {
      at += static_cast<std::size_t>(rows(c)) * per_row;
      continue;
    }
    std::vector<double>& out = send[static_cast<std::size_t>(o)];
    for (const std::size_t end = at + static_cast<std::size_t>(rows(c)) * per_row; at < end; ++at) {
      if (entry_weight_[at] == 0.0 || entry_local_[at] == kNotHere) continue;
      const double* v = node_velocity_.data() + 3 * entry_local_[at];
      out.insert(out.end(), v, v + 3);
    }
  }
  std::vector<int> from;
  const std::vector<double> in = all_to_all(send, fluid_.comm(), from);
  // Where each rank's values start.
  std::vector<std::size_t> next(static_cast<std::size_t>(slab.ranks), in.size());
  for (std::size_t i = in.size(); i-- > 0;) next[static_cast<std::size_t>(from[i])] = i;
  // Each owned vertex's velocity, summed over its stencil in the serial order (IbInterpolator).
  at = 0;
  for (int c : held_) {
    if (owner_[c] != me) {
      at += static_cast<std::size_t>(rows(c)) * per_row;
      continue;
    }
    for (Eigen::Index k = first_row(c); k < first_row(c) + rows(c); ++k) {
      Vec3 u = Vec3::Zero();
      for (const std::size_t end = at + per_row; at < end; ++at) {
        const double w = entry_weight_[at];
        if (w == 0.0) continue;
        const double* v;
        if (entry_local_[at] != kNotHere) {
          v = node_velocity_.data() + 3 * entry_local_[at];
        } else {
          std::size_t& i = next[static_cast<std::size_t>(entry_owner_[at])];
          v = in.data() + i;
          i += 3;
        }
        u += w * Vec3(v[0], v[1], v[2]);
      }
      U_.row(k) = u.transpose();
    }
  }
  // g. Move (explicit Euler, dt = 1), check, and wrap by a period, as LbmSuspension::step.
  for (int c : owned_) X_.middleRows(first_row(c), rows(c)) += 1.0 * U_.middleRows(first_row(c), rows(c));
  bool finite = true;
  for (int c : owned_) {
    for (Eigen::Index k = first_row(c); k < first_row(c) + rows(c) && finite; ++k) {
      if (!std::isfinite(X_(k, 0)) || !std::isfinite(X_(k, 1)) || !std::isfinite(X_(k, 2))) {
        fail(fmt::format("suspension blew up at step {}: vertex {} of cell {} has a non-finite position", n, k - first_row(c), c));
        finite = false;
      }
    }
  }
  if (finite)
    for (int c : owned_) wrap(c);
}

void MpiSuspension::wrap(int c) {
  const Vec3 period = options_.vessel.period();
  const Vec3 centre = X_.middleRows(first_row(c), rows(c)).colwise().mean().transpose();
  for (int a = 0; a < 2; ++a) {
    if (!options_.vessel.periodic(a)) continue;
    const double shift = period[a] * std::floor(centre[a] / period[a] + 0.5);  // into [-P/2, P/2)
    if (shift != 0) X_.middleRows(first_row(c), rows(c)).col(a).array() -= shift;
  }
}

Points MpiSuspension::gather_rows(const Points& M) const {
  // Each owner's cells: their indices, then their rows.
  const int ranks = fluid_.slab().ranks;
  MPI_Comm comm = fluid_.comm();
  std::vector<double> mine;
  for (int c : owned_) {
    mine.push_back(static_cast<double>(c));
    for (Eigen::Index k = first_row(c); k < first_row(c) + rows(c); ++k) mine.insert(mine.end(), {M(k, 0), M(k, 1), M(k, 2)});
  }
  int count = static_cast<int>(mine.size());
  std::vector<int> counts(static_cast<std::size_t>(ranks)), displs(static_cast<std::size_t>(ranks) + 1, 0);
  MPI_Allgather(&count, 1, MPI_INT, counts.data(), 1, MPI_INT, comm);
  for (int r = 0; r < ranks; ++r) displs[r + 1] = displs[r] + counts[r];
  std::vector<double> all(static_cast<std::size_t>(displs[ranks]));
  MPI_Allgatherv(mine.data(), count, MPI_DOUBLE, all.data(), counts.data(), displs.data(), MPI_DOUBLE, comm);
  Points X(M.rows(), 3);
  for (std::size_t at = 0; at < all.size();) {
    const int c = static_cast<int>(all[at++]);
    for (Eigen::Index k = first_row(c); k < first_row(c) + rows(c); ++k, at += 3) X.row(k) << all[at], all[at + 1], all[at + 2];
  }
  return X;
}

}  // namespace bendlab::parallel
