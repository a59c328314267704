#include "bendlab/suspension/contact.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace bendlab {

void ContactLaw::validate() const {
  if (!(max_force >= 0) || !std::isfinite(max_force)) throw Error(fmt::format("contact force {} must be finite and not negative", max_force));
  if (!(cutoff > 0) || !std::isfinite(cutoff)) throw Error(fmt::format("contact cutoff {} must be finite and positive", cutoff));
}

double ContactLaw::force(double r) const {
  if (r >= cutoff) return 0.0;
  const double s = 1.0 - std::max(r, 0.0) / cutoff;
  return max_force * s * s;
}

double ContactLaw::energy(double r) const {
  if (r >= cutoff) return 0.0;
  const double s = 1.0 - r / cutoff;  // past the wall (r < 0) the energy keeps growing, the force stays capped
  return r >= 0 ? max_force * cutoff / 3.0 * s * s * s : max_force * cutoff / 3.0 - max_force * r;
}

namespace {
// Coordinate a of x into [-P/2, P/2) along a periodic axis of period P (unchanged along others):
// the one wrapping of the bins and of the Verlet list's separations, so that they agree bit for bit.
double wrapped_coordinate(const Vessel& vessel, const Vec3& period, double c, int a) {
  return vessel.periodic(a) ? c - period[a] * std::floor((c + 0.5 * period[a]) / period[a]) : c;
}
}  // namespace

double add_wall_contact(const Vessel& vessel, const ContactLaw& law, const Points& x, Points& F) {
  double energy = 0;
  for (Eigen::Index i = 0; i < x.rows(); ++i) {
    const Vec3 p = row(x, i);
    const double d = vessel.wall_distance(p);
    if (d >= law.cutoff) continue;
    F.row(i) += law.force(d) * vessel.wall_normal(p).transpose();
    energy += law.energy(d);
  }
  return energy;
}

void ContactSearch::bin(const Vessel& vessel, const Points& x, const std::vector<int>& cell_of, double width) {
  const Eigen::Index n = x.rows();
  const Vec3 period = vessel.period();
  for (int a = 0; a < 3; ++a) {
    if (vessel.periodic(a)) {
      nb_[a] = std::max(1, static_cast<int>(std::floor(period[a] / width)));
      lo_[a] = -0.5 * period[a];
      w_[a] = period[a] / nb_[a];
    } else {
      const double lo = n > 0 ? x.col(a).minCoeff() : 0.0, hi = n > 0 ? x.col(a).maxCoeff() : 0.0;
      const double fit = std::floor((hi - lo) / width);  // NaN or huge where positions blew up
      nb_[a] = fit >= 1 ? static_cast<int>(std::min(fit, 1048576.0)) : 1;
      lo_[a] = std::isfinite(lo) ? lo : 0.0;
      w_[a] = std::max((hi - lo) / nb_[a], width);
    }
  }
  // At most about 8 bins per vertex: cells spread far apart along an axis without a period (or a
  // run blowing up) would otherwise ask for more bins than memory holds. Fewer, wider bins find
  // the same pairs.
  const double limit = 8.0 * static_cast<double>(n) + 64.0;
  while (static_cast<double>(nb_[0]) * nb_[1] * nb_[2] > limit) {
    int widest = -1;
    for (int a = 0; a < 3; ++a)
      if (!vessel.periodic(a) && nb_[a] > 1 && (widest < 0 || nb_[a] > nb_[widest])) widest = a;
    if (widest < 0) break;  // the periodic axes' bins are bounded by their periods
    nb_[widest] = (nb_[widest] + 1) / 2;
    w_[widest] *= 2;
  }
  const std::size_t bins = static_cast<std::size_t>(nb_[0]) * nb_[1] * nb_[2];
  bin_of_.resize(n);
  wrapped_.resize(n, 3);
  start_.assign(bins + 1, 0);
  items_.resize(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    int b[3];
    for (int a = 0; a < 3; ++a) {
      const double c = wrapped_coordinate(vessel, period, x(i, a), a);  // into [lo, lo + period)
      wrapped_(i, a) = c;
      const double at = std::floor((c - lo_[a]) / w_[a]);  // clamped before the cast: NaN goes to 0
      b[a] = at > 0 ? static_cast<int>(std::min(at, static_cast<double>(nb_[a] - 1))) : 0;
    }
    bin_of_[i] = b[0] + nb_[0] * (b[1] + nb_[1] * b[2]);
    ++start_[bin_of_[i] + 1];
  }
  for (std::size_t b = 0; b < bins; ++b) start_[b + 1] += start_[b];
  // Counting sort; start_ is shifted back afterwards.
  for (Eigen::Index i = 0; i < n; ++i) items_[start_[bin_of_[i]]++] = static_cast<int>(i);
  for (std::size_t b = bins; b > 0; --b) start_[b] = start_[b - 1];
  start_[0] = 0;
  // The wrapped positions and cells in bin order, for the pair loop to read front to back.
  sorted_.resize(n, 3);
  sorted_cell_.resize(n);
  for (Eigen::Index s = 0; s < n; ++s) {
    const int i = items_[s];
    sorted_.row(s) = wrapped_.row(i);
    sorted_cell_[s] = cell_of[i];
  }
  // Per bin: its one cell, kEmptyBin, or kMixedBin.
  bin_cell_.assign(bins, kEmptyBin);
  for (std::size_t b = 0; b < bins; ++b)
    for (int s = start_[b]; s < start_[b + 1]; ++s) {
      int& c = bin_cell_[b];
      c = c == kEmptyBin || c == sorted_cell_[s] ? sorted_cell_[s] : kMixedBin;
      if (c == kMixedBin) break;
    }
}

template <bool kBothSides, class Visit, class EndOfVertex>
void ContactSearch::for_each_pair(const Vessel& vessel, const Points& x, const std::vector<int>& cell_of, double range,
                                  Visit&& visit, EndOfVertex&& end_of_vertex) {
  if (static_cast<Eigen::Index>(cell_of.size()) != x.rows()) {
    throw Error(fmt::format("contact search: {} cell indices for {} vertices", cell_of.size(), x.rows()));
  }
  bin(vessel, x, cell_of, range);
  const double r2max = range * range;
  const Vec3 period = vessel.period();
  // With three bins or more along every periodic axis, each neighbour bin holds one image of its
  // vertices within range: the one shifted by the period when the neighbour wraps around. With
  // fewer, a bin can be its own neighbour on both sides and the nearest image is taken per pair.
  bool shifted_images = true;
  for (int a = 0; a < 3; ++a)
    if (vessel.periodic(a) && nb_[a] < 3) shifted_images = false;
  const int bins = nb_[0] * nb_[1] * nb_[2];
  for (int b = 0; b < bins; ++b) {
    if (start_[b] == start_[b + 1]) continue;
    const int home[3] = {b % nb_[0], (b / nb_[0]) % nb_[1], b / (nb_[0] * nb_[1])};
    // The distinct neighbour bins along each axis (fewer than 3 when the axis has fewer bins),
    // with the shift that brings their vertices next to this bin's.
    int nbrs[3][3], count[3];
    double shift[3][3];
    for (int a = 0; a < 3; ++a) {
      count[a] = 0;
      for (int o = -1; o <= 1; ++o) {
        int c = home[a] + o;
        double sh = 0;
        if (vessel.periodic(a)) {
          if (c < 0) {
            c += nb_[a];
            sh = -period[a];
          } else if (c >= nb_[a]) {
            c -= nb_[a];
            sh = period[a];
          }
        } else if (c < 0 || c >= nb_[a]) {
          continue;
        }
        if (std::find(nbrs[a], nbrs[a] + count[a], c) == nbrs[a] + count[a]) {
          nbrs[a][count[a]] = c;
          shift[a][count[a]++] = sh;
        }
      }
    }
    // Most bins see one cell only (the inside of a membrane far from the others): nothing to do.
    const int own = bin_cell_[b];
    bool foreign = own == kMixedBin;
    for (int iz = 0; iz < count[2] && !foreign; ++iz)
      for (int iy = 0; iy < count[1] && !foreign; ++iy)
        for (int ix = 0; ix < count[0] && !foreign; ++ix) {
          const int c = bin_cell_[nbrs[0][ix] + nb_[0] * (nbrs[1][iy] + nb_[1] * nbrs[2][iz])];
          foreign = c != kEmptyBin && c != own;
        }
    if (!foreign) continue;
    for (int t = start_[b]; t < start_[b + 1]; ++t) {
      const int i = items_[t];
      const int ci = sorted_cell_[t];
      const double xi = sorted_(t, 0), yi = sorted_(t, 1), zi = sorted_(t, 2);
      for (int iz = 0; iz < count[2]; ++iz) {
        for (int iy = 0; iy < count[1]; ++iy) {
          for (int ix = 0; ix < count[0]; ++ix) {
            const int nb = nbrs[0][ix] + nb_[0] * (nbrs[1][iy] + nb_[1] * nbrs[2][iz]);
            const double ox = xi - shift[0][ix], oy = yi - shift[1][iy], oz = zi - shift[2][iz];
            for (int s = start_[nb]; s < start_[nb + 1]; ++s) {
              if (sorted_cell_[s] == ci) continue;
              const int j = items_[s];
              if (!kBothSides && j <= i) continue;
              Vec3 d;
              if (shifted_images) {
                d = Vec3(ox - sorted_(s, 0), oy - sorted_(s, 1), oz - sorted_(s, 2));
              } else {
                d = vessel.minimum_image(row(x, i) - row(x, j));
              }
              const double r2 = d.squaredNorm();
              if (r2 < r2max) visit(i, j, d, std::sqrt(r2));
            }
          }
        }
      }
      end_of_vertex(i);
    }
  }
}

double ContactSearch::add_cell_contact_reference(const Vessel& vessel, const ContactLaw& law, const Points& x,
                                                 const std::vector<int>& cell_of, Points& F) {
  ++list_builds_;
  // Each vertex's force is summed over its partners in the order of their rows, not in the order
  // the bins give them (which depends on every vertex's position: the bins of an axis without a
  // period span the vertices present), so that it does not depend on the vertices beyond the
  // cutoff: a rank that holds only the cells near its own gets the serial force. Every pair is
  // found from both of its vertices, and each adds its own side; the energy counts a pair once.
  double energy = 0;
  partners_.clear();
  for_each_pair<true>(
      vessel, x, cell_of, law.cutoff,
      [&](int i, int j, const Vec3& d, double r) {
        partners_.push_back(Partner{j, d, r});
        if (j > i) energy += law.energy(r);
      },
      [&](int i) {
        if (partners_.empty()) return;
        std::sort(partners_.begin(), partners_.end(), [](const Partner& a, const Partner& b) { return a.row < b.row; });
        for (const Partner& p : partners_)
          if (p.r > 0) F.row(i) += (law.force(p.r) / p.r * p.d).transpose();  // r = 0: no direction
        partners_.clear();
      });
  return energy;
}

double ContactSearch::min_cell_distance(const Vessel& vessel, const Points& x, const std::vector<int>& cell_of, double range) {
  double m = range;
  for_each_pair<false>(vessel, x, cell_of, range, [&](int, int, const Vec3&, double r) { m = std::min(m, r); }, [](int) {});
  return m;
}

bool ContactSearch::list_is_current(const Vessel& vessel, const ContactLaw& law, const Points& x,
                                    const std::vector<int>& cell_of) const {
  if (list_cutoff_ != law.cutoff || list_period_ != vessel.period() || list_x_.rows() != x.rows() || list_cell_ != cell_of) return false;
  const double limit = 0.25 * (kSkinFraction * law.cutoff) * (kSkinFraction * law.cutoff);  // (skin / 2)^2
  for (Eigen::Index i = 0; i < x.rows(); ++i) {
    const double dx = x(i, 0) - list_x_(i, 0), dy = x(i, 1) - list_x_(i, 1), dz = x(i, 2) - list_x_(i, 2);
    if (!(dx * dx + dy * dy + dz * dz <= limit)) return false;  // a non-finite position rebuilds too
  }
  return true;
}

void ContactSearch::build_list(const Vessel& vessel, const ContactLaw& law, const Points& x, const std::vector<int>& cell_of) {
  ++list_builds_;
  // Two passes of the search, counting each row's partners and then filling them in, so that the
  // list is the only store of pairs (4 bytes each); each row's partners sorted afterwards.
  const Eigen::Index n = x.rows();
  const double range = (1.0 + kSkinFraction) * law.cutoff;
  list_start_.assign(static_cast<std::size_t>(n) + 1, 0);
  for_each_pair<true>(vessel, x, cell_of, range,
                      [&](int i, int, const Vec3&, double) { ++list_start_[static_cast<std::size_t>(i) + 1]; }, [](int) {});
  for (Eigen::Index i = 0; i < n; ++i) list_start_[static_cast<std::size_t>(i) + 1] += list_start_[static_cast<std::size_t>(i)];
  list_row_.resize(static_cast<std::size_t>(list_start_.back()));
  fill_.assign(list_start_.begin(), list_start_.end() - 1);
  for_each_pair<true>(vessel, x, cell_of, range,
                      [&](int i, int j, const Vec3&, double) { list_row_[static_cast<std::size_t>(fill_[static_cast<std::size_t>(i)]++)] = j; },
                      [](int) {});
  for (Eigen::Index i = 0; i < n; ++i)
    std::sort(list_row_.begin() + list_start_[static_cast<std::size_t>(i)], list_row_.begin() + list_start_[static_cast<std::size_t>(i) + 1]);
  list_x_ = x;
  list_cell_ = cell_of;
  list_cutoff_ = law.cutoff;
  list_period_ = vessel.period();
}

double ContactSearch::add_cell_contact(const Vessel& vessel, const ContactLaw& law, const Points& x,
                                       const std::vector<int>& cell_of, Points& F) {
  if (static_cast<Eigen::Index>(cell_of.size()) != x.rows()) {
    throw Error(fmt::format("contact search: {} cell indices for {} vertices", cell_of.size(), x.rows()));
  }
  if (!list_is_current(vessel, law, x, cell_of)) build_list(vessel, law, x, cell_of);
  // The separations as the search in every call takes them (for_each_pair): with three bins of
  // r_c or more along every periodic axis, from the positions wrapped into the period, the
  // partner's image shifted by the period multiple that brings it within half a period (the
  // neighbour bin's shift for every pair closer than r_c); else the nearest image of x_i - x_j.
  const Vec3 period = vessel.period();
  bool shifted_images = true;
  for (int a = 0; a < 3; ++a)
    if (vessel.periodic(a) && static_cast<int>(std::floor(period[a] / law.cutoff)) < 3) shifted_images = false;
  const Eigen::Index n = x.rows();
  wrapped_.resize(n, 3);
  for (Eigen::Index i = 0; i < n; ++i)
    for (int a = 0; a < 3; ++a) wrapped_(i, a) = wrapped_coordinate(vessel, period, x(i, a), a);
  const double r2max = law.cutoff * law.cutoff;
  double energy = 0;
  for (Eigen::Index i = 0; i < n; ++i) {
    for (int k = list_start_[static_cast<std::size_t>(i)]; k < list_start_[static_cast<std::size_t>(i) + 1]; ++k) {
      const int j = list_row_[static_cast<std::size_t>(k)];
      Vec3 d;
      if (shifted_images) {
        for (int a = 0; a < 3; ++a) {
          const double shift = vessel.periodic(a) ? period[a] * std::round((wrapped_(i, a) - wrapped_(j, a)) / period[a]) : 0.0;
          d[a] = (wrapped_(i, a) - shift) - wrapped_(j, a);
        }
      } else {
        d = vessel.minimum_image(row(x, i) - row(x, j));
      }
      const double r2 = d.squaredNorm();
      if (!(r2 < r2max)) continue;
      const double r = std::sqrt(r2);
      if (j > i) energy += law.energy(r);
      if (r > 0) F.row(i) += (law.force(r) / r * d).transpose();  // r = 0: no direction
    }
  }
  return energy;
}

}  // namespace bendlab
