#include "bendlab/suspension/placement_growth.hpp"

#include <algorithm>
#include <cmath>
#include <random>

#include "bendlab/suspension/contact.hpp"
#include "placement_checks.hpp"

namespace bendlab {

namespace {

using placement_detail::apart;
using placement_detail::Candidate;
using placement_detail::clear_of_wall;
using placement_detail::random_rotation;

constexpr double kFirstScale = 0.6, kSmallestScale = 0.3, kScaleStep = 0.02;
constexpr int kAttemptsPerCell = 2000, kRelaxIterations = 1500, kFinalRounds = 4;
constexpr double kDoneForce = 1e-4;  // (1 % of the target distance)^2

struct Body {
  Mat3 rotation;
  Vec3 centre;
};

// The vertices of every body at scale s, body after body.
void positions(const std::vector<Body>& bodies, const Points& reference, double s, Points& x) {
  const Eigen::Index n = reference.rows();
  x.resize(n * static_cast<Eigen::Index>(bodies.size()), 3);
  for (std::size_t b = 0; b < bodies.size(); ++b) {
    x.middleRows(static_cast<Eigen::Index>(b) * n, n) = (s * reference) * bodies[b].rotation.transpose();
    x.middleRows(static_cast<Eigen::Index>(b) * n, n).rowwise() += bodies[b].centre.transpose();
  }
}

// Random sequential addition of `count` bodies at scale s (the exact checks at that size), or
// nothing where one does not fit within its attempts.
std::optional<std::vector<Body>> place_shrunk(const Vessel& vessel, const Topology& topo, const Points& reference,
                                              int count, double s, double clearance, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-0.5, 0.5);
  const Points shrunk = s * reference;
  double extent = 0;
  for (Eigen::Index i = 0; i < shrunk.rows(); ++i) extent = std::max(extent, shrunk.row(i).norm());
  const Vec3 period = vessel.period();
  const BoundingBox frame_box = bounding_box(shrunk);
  const double slack = 1e-9 * extent;
  std::vector<Body> bodies;
  std::vector<Candidate> placed;
  for (int c = 0; c < count; ++c) {
    bool ok = false;
    for (int attempt = 0; attempt < kAttemptsPerCell && !ok; ++attempt) {
      const Mat3 R = random_rotation(rng);
      const Vec3 centre(u(rng) * vessel.length(), u(rng) * vessel.width(), u(rng) * vessel.height());
      Candidate cand{shrunk * R.transpose(), {}, centre, R};
      cand.x.rowwise() += centre.transpose();
      if (!clear_of_wall(vessel, cand.x, clearance)) continue;
      cand.box = bounding_box(cand.x);
      ok = true;
      for (const Candidate& other : placed) {
        const Vec3 d = vessel.minimum_image(other.centre - cand.centre) - (other.centre - cand.centre);
        for (int sx = -1; sx <= 1 && ok; ++sx)
          for (int sy = vessel.periodic(1) ? -1 : 0; sy <= (vessel.periodic(1) ? 1 : 0) && ok; ++sy) {
            const Vec3 shift = d + Vec3(sx * period.x(), sy * period.y(), 0);
            if ((other.centre + shift - cand.centre).norm() > 2 * extent + clearance) continue;
            ok = apart(topo, cand, other, shift, clearance, frame_box, slack);
          }
        if (!ok) break;
      }
      if (ok) {
        bodies.push_back(Body{R, centre});
        placed.push_back(std::move(cand));
      }
    }
    if (!ok) return std::nullopt;
  }
  return bodies;
}

// Pushes the bodies at scale s apart until no vertex is nearer than `target` to a vertex of another
// body or to the wall (header, step 2); whether that was reached.
bool relax(const Vessel& vessel, std::vector<Body>& bodies, const Points& reference, double s, double target,
           const std::vector<int>& body_of, ContactSearch& search) {
  const Eigen::Index n = reference.rows();
  double gyration2 = 0;
  for (Eigen::Index i = 0; i < n; ++i) gyration2 += reference.row(i).squaredNorm();
  gyration2 = std::max(s * s * gyration2 / static_cast<double>(n), 1e-12);
  const ContactLaw law{1.0, target};
  Points x, F;
  const Vec3 period = vessel.period();
  for (int iteration = 0; iteration < kRelaxIterations; ++iteration) {
    positions(bodies, reference, s, x);
    F.setZero(x.rows(), 3);
    search.add_cell_contact(vessel, law, x, body_of, F);
    add_wall_contact(vessel, law, x, F);
    // Done when no vertex overlaps its target by more than 1 % of it (a force of 1e-4).
    const double largest = F.rowwise().norm().maxCoeff();
    if (largest <= kDoneForce) return true;
    for (std::size_t b = 0; b < bodies.size(); ++b) {
      Vec3 push = Vec3::Zero(), torque = Vec3::Zero();
      int touching = 0;
      for (Eigen::Index i = static_cast<Eigen::Index>(b) * n; i < static_cast<Eigen::Index>(b + 1) * n; ++i) {
        const Vec3 f = row(F, i);
        const double magnitude = f.norm();
        if (magnitude == 0) continue;
        ++touching;
        // The law's force is (overlap / t)^2: the push that undoes the overlap, shared by the
        // two sides (a little more than half each).
        const Vec3 undo = 0.6 * target * std::sqrt(std::min(magnitude, 1.0)) / magnitude * f;
        push += undo;
        torque += (row(x, i) - bodies[b].centre).cross(undo);
      }
      if (touching == 0) continue;
      // The mean push moves the body; the torque of the pushes turns it about its centre.
      Body& body = bodies[b];
      body.centre += push / touching;
      const Vec3 turn = torque / (touching * gyration2);
      const double angle = std::min(turn.norm(), 0.05);
      if (angle > 0) body.rotation = Eigen::AngleAxisd(angle, turn.normalized()).toRotationMatrix() * body.rotation;
      for (int a = 0; a < 2; ++a)  // back into the period
        if (vessel.periodic(a)) body.centre[a] -= period[a] * std::floor(body.centre[a] / period[a] + 0.5);
    }
  }
  return false;
}

// The exact checks at full size (header, step 3).
bool all_apart(const Vessel& vessel, const Topology& topo, const Points& reference, const std::vector<Body>& bodies,
               double clearance) {
  double extent = 0;
  for (Eigen::Index i = 0; i < reference.rows(); ++i) extent = std::max(extent, reference.row(i).norm());
  const Vec3 period = vessel.period();
  const BoundingBox frame_box = bounding_box(reference);
  const double slack = 1e-9 * extent;
  std::vector<Candidate> cells;
  for (const Body& b : bodies) {
    Candidate c{reference * b.rotation.transpose(), {}, b.centre, b.rotation};
    c.x.rowwise() += b.centre.transpose();
    if (!clear_of_wall(vessel, c.x, clearance)) return false;
    c.box = bounding_box(c.x);
    cells.push_back(std::move(c));
  }
  for (std::size_t a = 0; a < cells.size(); ++a)
    for (std::size_t b = a + 1; b < cells.size(); ++b) {
      const Vec3 d = vessel.minimum_image(cells[b].centre - cells[a].centre) - (cells[b].centre - cells[a].centre);
      for (int sx = -1; sx <= 1; ++sx)
        for (int sy = vessel.periodic(1) ? -1 : 0; sy <= (vessel.periodic(1) ? 1 : 0); ++sy) {
          const Vec3 shift = d + Vec3(sx * period.x(), sy * period.y(), 0);
          if ((cells[b].centre + shift - cells[a].centre).norm() > 2 * extent + clearance) continue;
          if (!apart(topo, cells[a], cells[b], shift, clearance, frame_box, slack)) return false;
        }
    }
  return true;
}

}  // namespace

std::optional<std::vector<PlacedCell>> grow_cells(const Vessel& vessel, const Topology& topology, const Points& reference,
                                                  int count, double clearance, std::uint64_t seed) {
  if (count <= 0) return std::vector<PlacedCell>{};
  // A clearance of zero still needs a distance to push to.
  const double spacing = std::max(clearance, 1e-3 * vessel.height());
  std::mt19937_64 rng(seed);
  std::optional<std::vector<Body>> bodies;
  double s = kFirstScale;
  for (; s >= kSmallestScale - 1e-12 && !bodies; s -= 0.1) bodies = place_shrunk(vessel, topology, reference, count, s, clearance, rng);
  if (!bodies) return std::nullopt;
  s += 0.1;  // the scale that placed them
  std::vector<int> body_of(static_cast<std::size_t>(count) * reference.rows());
  for (std::size_t i = 0; i < body_of.size(); ++i) body_of[i] = static_cast<int>(i / reference.rows());
  ContactSearch search;
  // Vertices kept apart by more than the clearance and more than half an edge, so that a vertex
  // cannot sit inside the other cell between its vertices (a coarse mesh's edges are long).
  double edge = 0;
  for (int e = 0; e < topology.num_edges(); ++e) {
    const auto& ends = topology.edge_vertices();
    edge += (reference.row(ends(e, 0)) - reference.row(ends(e, 1))).norm();
  }
  edge /= std::max(1, topology.num_edges());
  double target = std::max(1.2 * spacing, 0.6 * edge);
  while (s < 1.0) {
    s = std::min(1.0, s + kScaleStep);
    if (!relax(vessel, *bodies, reference, s, target, body_of, search)) return std::nullopt;
  }
  for (int round = 0; round < kFinalRounds; ++round) {
    if (all_apart(vessel, topology, reference, *bodies, clearance)) {
      std::vector<PlacedCell> cells;
      for (const Body& b : *bodies) cells.push_back(PlacedCell{b.rotation, b.centre});
      return cells;
    }
    target *= 1.25;  // a vertex inside another cell between its vertices: push them further apart
    if (!relax(vessel, *bodies, reference, 1.0, target, body_of, search)) return std::nullopt;
  }
  return std::nullopt;
}

}  // namespace bendlab
