#include "bendlab/suspension/placement.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <string>

#include "bendlab/geometry/point_in_mesh.hpp"
#include "bendlab/mesh/enclosed_volume.hpp"
#include "bendlab/suspension/cell_growth.hpp"

namespace bendlab {

namespace {

// Shoemake's uniform random rotation.
Mat3 random_rotation(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double u1 = u(rng), u2 = 2 * std::numbers::pi * u(rng), u3 = 2 * std::numbers::pi * u(rng);
  const Eigen::Quaterniond q(std::sqrt(u1) * std::cos(u3), std::sqrt(1 - u1) * std::sin(u2), std::sqrt(1 - u1) * std::cos(u2),
                             std::sqrt(u1) * std::sin(u3));
  return q.normalized().toRotationMatrix();
}

// The reference z axis turned onto x, spun about it and tilted by up to `max_tilt`.
Mat3 aligned_rotation(std::mt19937_64& rng, double max_tilt) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const Eigen::AngleAxisd spin(2 * std::numbers::pi * u(rng), Vec3::UnitZ());
  const Eigen::AngleAxisd onto_x(0.5 * std::numbers::pi, Vec3::UnitY());  // z -> x
  const double tilt = max_tilt * u(rng), about = 2 * std::numbers::pi * u(rng);
  const Eigen::AngleAxisd tilted(tilt, Vec3(0, std::cos(about), std::sin(about)));
  return (tilted * onto_x * spin).toRotationMatrix();
}

// The middle of the widest gap between the cells' centres along the periodic x axis (the whole
// period when there are none).
double widest_gap_middle(const std::vector<double>& xs, double length, double& gap) {
  if (xs.empty()) {
    gap = length;
    return 0;
  }
  std::vector<double> sorted;
  for (double x : xs) sorted.push_back(x - length * std::floor(x / length + 0.5));  // into [-L/2, L/2)
  std::sort(sorted.begin(), sorted.end());
  gap = -1;
  double middle = 0;
  for (std::size_t i = 0; i < sorted.size(); ++i) {
    const double next = i + 1 < sorted.size() ? sorted[i + 1] : sorted[0] + length;
    if (next - sorted[i] > gap) {
      gap = next - sorted[i];
      middle = 0.5 * (sorted[i] + next);
    }
  }
  return middle;
}

struct Candidate {
  Points x;
  BoundingBox box;
  Vec3 centre;
  Mat3 rotation;
};

bool clear_of_wall(const Vessel& v, const Points& x, double clearance) {
  for (Eigen::Index i = 0; i < x.rows(); ++i) {
    if (v.wall_distance(row(x, i)) < clearance) return false;
  }
  return true;
}

// Whether cells a and b (b shifted by `shift`, a periodic image) keep the clearance and neither
// holds a vertex of the other. A vertex is first set against the other cell's box in that cell's
// own frame (`frame_box`, the reference's box, widened by `slack` against rounding): outside it,
// widened by the clearance, it is near none of the other's vertices, and outside it, inside
// none of it, so the tests it skips could not fail and the answer is the same.
bool apart(const Topology& topo, const Candidate& a, const Candidate& b, const Vec3& shift, double clearance,
           const BoundingBox& frame_box, double slack) {
  Points bx = b.x;
  bx.rowwise() += shift.transpose();
  BoundingBox bb{b.box.lo + shift, b.box.hi + shift};
  // Boxes farther apart than the clearance: nothing to check.
  if (((a.box.lo.array() - bb.hi.array()) >= clearance).any() || ((bb.lo.array() - a.box.hi.array()) >= clearance).any()) return true;
  const double c2 = clearance * clearance;
  const Vec3 b_centre = b.centre + shift;
  for (Eigen::Index i = 0; i < a.x.rows(); ++i) {
    const Vec3 p = row(a.x, i);
    if (!bb.contains(p, clearance)) continue;
    const Vec3 q = b.rotation.transpose() * (p - b_centre);
    if (!frame_box.contains(q, clearance + slack)) continue;
    for (Eigen::Index j = 0; j < bx.rows(); ++j) {
      if ((p - row(bx, j)).squaredNorm() < c2) return false;
    }
    if (frame_box.contains(q, slack) && contains(topo, bx, bb, p)) return false;
  }
  for (Eigen::Index j = 0; j < bx.rows(); ++j) {
    const Vec3 p = row(bx, j);
    if (!frame_box.contains(a.rotation.transpose() * (p - a.centre), slack)) continue;
    if (contains(topo, a.x, a.box, p)) return false;
  }
  return true;
}

}  // namespace

Points placed_positions(const Points& reference, const PlacedCell& cell) {
  Points x = reference * cell.rotation.transpose();
  x.rowwise() += cell.centre.transpose();
  return x;
}

namespace {

struct Addition {
  std::vector<PlacedCell> cells;
  std::int64_t attempts = 0;
  int failed = -1;  ///< the cell that failed its attempts, -1 when all are placed
};

// Random sequential addition of `target` copies of the reference shape (header comment).
Addition random_sequential_addition(const Vessel& vessel, const Topology& topo, const Points& reference, int target,
                                    double clearance, int attempts_per_cell, std::uint64_t seed, bool narrow) {
  Addition result;
  double extent = 0;
  for (Eigen::Index i = 0; i < reference.rows(); ++i) extent = std::max(extent, reference.row(i).norm());
  const double half_width = vessel.kind() == VesselKind::Tube ? 0.5 * vessel.diameter() : 0.5 * vessel.height();
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-0.5, 0.5);
  std::vector<Candidate> placed;
  placed.reserve(target);
  std::vector<double> centres_x;
  const BoundingBox frame_box = bounding_box(reference);
  const double slack = 1e-9 * extent;
  const double x0 = u(rng) * vessel.length();
  const Vec3 period = vessel.period();
  for (int c = 0; c < target; ++c) {
    bool ok = false;
    for (int attempt = 0; attempt < attempts_per_cell && !ok; ++attempt) {
      ++result.attempts;
      const bool aligned = narrow || attempt >= attempts_per_cell / 2;
      // In a narrow tube the tilt and the jitter shrink as the attempts go by, down to a cell
      // square to the axis in the middle of its slot.
      const double freedom = narrow ? 1.0 - static_cast<double>(attempt) / attempts_per_cell : 1.0;
      const Mat3 R = aligned ? aligned_rotation(rng, freedom * std::numbers::pi / 6) : random_rotation(rng);
      Vec3 centre(u(rng) * vessel.length(), u(rng) * vessel.width(), u(rng) * vessel.height());
      if (narrow) {
        // Stacked along the tube in equal slots from a random start.
        const double slot = vessel.length() / target;
        centre.x() = x0 + (c + 0.5) * slot + freedom * 0.5 * slot * u(rng);
      } else if (aligned && vessel.kind() == VesselKind::Tube) {
        // Into the widest gap between the cells placed along the tube, jittered.
        double gap = 0;
        centre.x() = widest_gap_middle(centres_x, vessel.length(), gap) + 0.25 * gap * u(rng);
      }
      if (vessel.kind() == VesselKind::Tube || aligned) {
        // Uniform in the disc (tube) or slab (others) left by the wall; aligned cells near the axis.
        const double reach = std::max(half_width - (aligned ? 0.8 * half_width : 0.0), 0.0) * (narrow ? freedom : 1.0);
        if (vessel.kind() == VesselKind::Tube) {
          const double r = reach * std::sqrt(u(rng) + 0.5), phi = 2 * std::numbers::pi * u(rng);
          centre.y() = r * std::cos(phi);
          centre.z() = r * std::sin(phi);
        } else {
          centre.z() = 2 * reach * u(rng);
        }
      }
      Candidate cand{placed_positions(reference, PlacedCell{R, centre}), {}, centre, R};
      if (!clear_of_wall(vessel, cand.x, clearance)) continue;
      cand.box = bounding_box(cand.x);
      ok = true;
      for (const Candidate& other : placed) {
        // The nearest image of the other cell, and its neighbours along the periodic axes when the
        // cells are large against the period.
        const Vec3 d = vessel.minimum_image(other.centre - cand.centre) - (other.centre - cand.centre);
        for (int sx = -1; sx <= 1 && ok; ++sx) {
          for (int sy = vessel.periodic(1) ? -1 : 0; sy <= (vessel.periodic(1) ? 1 : 0) && ok; ++sy) {
            const Vec3 shift = d + Vec3(sx * period.x(), sy * period.y(), 0);
            if ((other.centre + shift - cand.centre).norm() > 2 * extent + clearance) continue;
            ok = apart(topo, cand, other, shift, clearance, frame_box, slack);
          }
        }
        if (!ok) break;
      }
      if (ok) {
        placed.push_back(std::move(cand));
        result.cells.push_back(PlacedCell{R, centre});
        centres_x.push_back(centre.x());
      }
    }
    if (!ok) {
      result.failed = c;
      return result;
    }
  }
  return result;
}

// The exact check of grown cells on the meshes: every vertex at least `clearance` from the wall
// and from every vertex of another cell (periodic images, a cell's own included), none inside
// another cell (winding number). A vertex outside the other cell's box in that cell's own frame
// (widened by the clearance) is near none of its vertices and inside none of it.
bool apart_on_meshes(const Vessel& vessel, const Topology& topo, const Points& reference, const std::vector<PlacedCell>& cells,
                     double clearance) {
  const BoundingBox box = bounding_box(reference);
  double extent = 0;
  for (Eigen::Index i = 0; i < reference.rows(); ++i) extent = std::max(extent, reference.row(i).norm());
  std::vector<Points> world;
  world.reserve(cells.size());
  for (const PlacedCell& c : cells) {
    world.push_back(placed_positions(reference, c));
    if (!clear_of_wall(vessel, world.back(), clearance)) return false;
  }
  const double c2 = clearance * clearance;
  // The vertices of cell a against cell b moved by `shift`, in b's frame.
  auto one_way = [&](std::size_t a, std::size_t b, const Vec3& shift) {
    const Mat3& Rb = cells[b].rotation;
    const Vec3 cb = cells[b].centre + shift;
    for (Eigen::Index i = 0; i < world[a].rows(); ++i) {
      const Vec3 q = Rb.transpose() * (row(world[a], i) - cb);
      if (!box.contains(q, clearance)) continue;
      for (Eigen::Index j = 0; j < reference.rows(); ++j) {
        if ((q - row(reference, j)).squaredNorm() < c2) return false;
      }
      if (contains(topo, reference, box, q)) return false;
    }
    return true;
  };
  const Vec3 period = vessel.period();
  const int ny = vessel.periodic(1) ? 1 : 0;
  for (std::size_t a = 0; a < cells.size(); ++a) {
    for (std::size_t b = a; b < cells.size(); ++b) {
      const Vec3 sep = cells[b].centre - cells[a].centre;
      const Vec3 d0 = vessel.minimum_image(sep) - sep;
      for (int sx = -1; sx <= 1; ++sx) {
        for (int sy = -ny; sy <= ny; ++sy) {
          if (a == b && !(sx > 0 || (sx == 0 && sy > 0))) continue;
          const Vec3 shift = d0 + Vec3(sx * period.x(), sy * period.y(), 0);
          if ((sep + shift).norm() > 2 * extent + clearance) continue;
          if (!one_way(a, b, shift) || !one_way(b, a, -shift)) return false;
        }
      }
    }
  }
  return true;
}

// SplitMix64: a seed for the shrunk cells' addition, apart from the first addition's.
std::uint64_t derived_seed(std::uint64_t seed) {
  std::uint64_t z = seed + 0x9E3779B97F4A7C15ull;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

}  // namespace

Placement place_cells(const Vessel& vessel, const Topology& topo, const Points& reference, const PlacementOptions& o) {
  if (o.hematocrit.has_value() == o.count.has_value()) throw Error("cell placement: give either a hematocrit or a number of cells");
  if (!(o.clearance >= 0) || !std::isfinite(o.clearance)) throw Error(fmt::format("cell placement: clearance {} must be finite and not negative", o.clearance));
  if (o.attempts_per_cell < 1) throw Error("cell placement: at least one attempt per cell");
  Placement result;
  result.cell_volume = enclosed_volume(topo, reference);
  if (!(result.cell_volume > 0)) throw Error("cell placement: the cell's volume is not positive");
  int target = 0;
  if (o.hematocrit) {
    const double h = *o.hematocrit;
    if (!(h >= 0) || !std::isfinite(h) || h >= 1) throw Error(fmt::format("--hematocrit {} must lie in [0, 1)", h));
    target = static_cast<int>(std::lround(h * vessel.volume() / result.cell_volume));
    if (h > 0 && target == 0) {
      throw Error(fmt::format("--hematocrit {} is less than one cell in the {} (one cell is {:.3g})", h, vessel.describe(),
                              result.cell_volume / vessel.volume()));
    }
  } else {
    if (*o.count < 0) throw Error(fmt::format("--cells {} must not be negative", *o.count));
    target = *o.count;
  }
  double extent = 0;
  for (Eigen::Index i = 0; i < reference.rows(); ++i) extent = std::max(extent, reference.row(i).norm());
  const double half_width = vessel.kind() == VesselKind::Tube ? 0.5 * vessel.diameter() : 0.5 * vessel.height();
  // A tube less than two cell diameters across holds its cells stacked along the axis, as red
  // blood cells go through capillaries: every attempt aligns the cell with the flow.
  const bool narrow = vessel.kind() == VesselKind::Tube && half_width < 2 * extent;
  Addition added = random_sequential_addition(vessel, topo, reference, target, o.clearance, o.attempts_per_cell, o.seed, narrow);
  result.attempts = added.attempts;
  const double vessel_volume = vessel.volume();
  if (added.failed < 0) {
    result.cells = std::move(added.cells);
    result.hematocrit = static_cast<double>(result.cells.size()) * result.cell_volume / vessel_volume;
    return result;
  }

  // Jammed: all the cells again, shrunk, grown to full size (header comment). A narrow tube
  // stacks them only where the stack fits along it.
  const double thickness = reference.col(2).maxCoeff() - reference.col(2).minCoeff();
  const bool stacked = narrow && target * (thickness + o.clearance) <= vessel.length();
  GrowthOptions grow;
  grow.clearance = o.clearance;
  grow.margin = 0.1 * o.clearance + 0.002 * extent;
  std::uint64_t seed = o.seed;
  double reached = 0, tried_scale = 0;
  bool failed_check = false;
  for (double s0 : {0.6, 0.45, 0.3}) {
    seed = derived_seed(seed);
    Addition shrunk = random_sequential_addition(vessel, topo, s0 * reference, target, o.clearance, o.attempts_per_cell, seed, stacked);
    result.attempts += shrunk.attempts;
    if (shrunk.failed >= 0) continue;
    grow.initial_scale = s0;
    tried_scale = s0;
    const GrowthResult grown = grow_cells(vessel, topo, reference, shrunk.cells, grow);
    result.sweeps = grown.sweeps;
    reached = grown.scale;
    failed_check = grown.grown && !apart_on_meshes(vessel, topo, reference, shrunk.cells, o.clearance);
    if (grown.grown && !failed_check) {
      result.cells = std::move(shrunk.cells);
      result.initial_scale = s0;
      result.hematocrit = static_cast<double>(result.cells.size()) * result.cell_volume / vessel_volume;
      return result;
    }
    break;  // the packing jammed, not the start: a smaller start would jam as well
  }
  const double best = static_cast<double>(added.cells.size()) * result.cell_volume / vessel_volume;
  const double grown_best = target * reached * reached * reached * result.cell_volume / vessel_volume;
  const std::string growth =
      failed_check ? fmt::format("; grown from {:g} of their size, the {} cells reached full size but failed the check on the meshes",
                                 tried_scale, target)
      : tried_scale > 0 ? fmt::format("; grown from {:g} of their size, the {} cells stopped at {:.3f} of it (H_T {:.4f})", tried_scale,
                                    target, reached, grown_best)
                      : fmt::format("; {} cells shrunk to 0.3 of their size could not be placed either", target);
  throw Error(fmt::format("cannot place {} cells (H_T {:.4f}) in the {}: {} placed (H_T {:.4f}) before cell {} failed {} attempts{}",
                          target, target * result.cell_volume / vessel_volume, vessel.describe(), added.cells.size(), best,
                          added.failed + 1, o.attempts_per_cell, growth));
}

}  // namespace bendlab
