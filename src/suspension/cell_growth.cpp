#include "bendlab/suspension/cell_growth.hpp"

#include "bendlab/geometry/point_in_mesh.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace bendlab {

namespace {

// The point of triangle (a, b, c) nearest to p (Ericson, Real-Time Collision Detection 5.1.5) and
// the feature it lies on: corner k (0..2), the edge opposite corner k (3 + k) or the face (6).
Vec3 closest_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c, int& feature) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) {
    feature = 0;
    return a;
  }
  const Vec3 bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) {
    feature = 1;
    return b;
  }
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    feature = 3 + 2;
    return a + (d1 / (d1 - d3)) * ab;
  }
  const Vec3 cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) {
    feature = 2;
    return c;
  }
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    feature = 3 + 1;
    return a + (d2 / (d2 - d6)) * ac;
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) {
    feature = 3 + 0;
    return b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b);
  }
  const double denom = 1.0 / (va + vb + vc);
  feature = 6;
  return a + ab * (vb * denom) + ac * (vc * denom);
}

}  // namespace

MeshDistance::MeshDistance(const Topology& topology, const Points& x, double band) : topology_(&topology), x_(x), band_(band) {
  const Faces& F = topology.faces();
  const int nf = topology.num_faces();
  face_normal_.resize(nf);
  vertex_normal_.assign(x.rows(), Vec3::Zero());
  centroid_.resize(nf);
  radius_.resize(nf);
  std::vector<Vec3>& centroid = centroid_;
  std::vector<double>& radius = radius_;
  for (int f = 0; f < nf; ++f) {
    const Vec3 a = row(x, F(f, 0)), b = row(x, F(f, 1)), c = row(x, F(f, 2));
    face_normal_[f] = (b - a).cross(c - a).normalized();
    centroid[f] = (a + b + c) / 3;
    radius[f] = std::max({(a - centroid[f]).norm(), (b - centroid[f]).norm(), (c - centroid[f]).norm()});
    for (int k = 0; k < 3; ++k) {
      const Vec3 p = row(x, F(f, k)), u = row(x, F(f, (k + 1) % 3)) - p, v = row(x, F(f, (k + 2) % 3)) - p;
      vertex_normal_[F(f, k)] += std::atan2(u.cross(v).norm(), u.dot(v)) * face_normal_[f];
    }
  }
  edge_normal_.resize(topology.num_edges());
  double mean_edge = 0;
  for (int e = 0; e < topology.num_edges(); ++e) {
    edge_normal_[e] = face_normal_[topology.edge_faces()(e, 0)] + face_normal_[topology.edge_faces()(e, 1)];
    mean_edge += (row(x, topology.edge_vertices()(e, 0)) - row(x, topology.edge_vertices()(e, 1))).norm();
  }
  mean_edge /= std::max(topology.num_edges(), 1);

  // Grid cells half an edge wide (fewer where that would make too many), over the mesh's box
  // widened by the band and one cell.
  const Vec3 xlo = x.colwise().minCoeff().transpose(), xhi = x.colwise().maxCoeff().transpose();
  h_ = 0.5 * mean_edge;
  for (;;) {
    lo_ = xlo - Vec3::Constant(band + h_);
    long total = 1;
    for (int d = 0; d < 3; ++d) {
      n_[d] = std::max(1, static_cast<int>(std::ceil((xhi[d] + band + h_ - lo_[d]) / h_)));
      total *= n_[d];
    }
    if (total <= 200000) break;
    h_ *= 1.25;
  }
  inv_h_ = 1 / h_;
  const double e = 0.5 * std::sqrt(3.0) * h_;  // half a cell's diagonal
  start_.assign(static_cast<std::size_t>(n_[0]) * n_[1] * n_[2] + 1, 0);
  std::vector<double> dist(nf);  // to each triangle from the cell's centre, or a lower bound
  std::vector<char> exact(nf);
  std::size_t cell = 0;
  for (int i = 0; i < n_[0]; ++i) {
    for (int j = 0; j < n_[1]; ++j) {
      for (int k = 0; k < n_[2]; ++k, ++cell) {
        const Vec3 g = lo_ + h_ * Vec3(i + 0.5, j + 0.5, k + 0.5);
        // The nearest triangle to the cell's centre, the bounds |g - centroid| -+ radius sparing
        // most of the exact distances.
        double best = std::numeric_limits<double>::infinity();
        int best_face = -1, best_feature = 6;
        Vec3 best_point = g;
        for (int f = 0; f < nf; ++f) {
          dist[f] = (g - centroid[f]).norm() - radius[f];
          exact[f] = 0;
          if (dist[f] >= best) continue;
          int feature = 6;
          const Vec3 q = closest_on_triangle(g, row(x, F(f, 0)), row(x, F(f, 1)), row(x, F(f, 2)), feature);
          dist[f] = (g - q).norm();
          exact[f] = 1;
          if (dist[f] < best) {
            best = dist[f];
            best_face = f;
            best_feature = feature;
            best_point = q;
          }
        }
        const bool inside = (g - best_point).dot(pseudo_normal(best_face, best_feature)) < 0;
        // A point of the cell is within e of g: its nearest triangle lies within best + 2e of g.
        // Cells farther outside than the band keep none.
        if (inside || best <= band + e) {
          // Nearest first, so that a query's bound skips most of the rest.
          const std::size_t first = faces_.size();
          for (int f = 0; f < nf; ++f) {
            if (dist[f] > best + 2 * e) continue;
            if (!exact[f]) {
              int feature = 6;
              const Vec3 q = closest_on_triangle(g, row(x, F(f, 0)), row(x, F(f, 1)), row(x, F(f, 2)), feature);
              dist[f] = (g - q).norm();
              if (dist[f] > best + 2 * e) continue;
            }
            faces_.push_back(f);
          }
          std::stable_sort(faces_.begin() + static_cast<std::ptrdiff_t>(first), faces_.end(),
                           [&](int f1, int f2) { return dist[f1] < dist[f2]; });
        }
        start_[cell + 1] = static_cast<int>(faces_.size());
      }
    }
  }
}

bool MeshDistance::near(const Vec3& centre, double radius) const {
  double d2 = 0;
  for (int k = 0; k < 3; ++k) {
    const double hi = lo_[k] + n_[k] * h_;
    const double out = centre[k] < lo_[k] ? lo_[k] - centre[k] : centre[k] > hi ? centre[k] - hi : 0.0;
    d2 += out * out;
  }
  return d2 <= radius * radius;
}

Vec3 MeshDistance::pseudo_normal(int face, int feature) const {
  if (feature < 3) return vertex_normal_[topology_->faces()(face, feature)];
  if (feature < 6) return edge_normal_[topology_->face_edges()(face, feature - 3)];
  return face_normal_[face];
}

bool MeshDistance::query(const Vec3& p, Hit& hit) const {
  int idx[3];
  for (int d = 0; d < 3; ++d) {
    const double t = (p[d] - lo_[d]) * inv_h_;
    if (!(t >= 0) || t >= n_[d]) return false;
    idx[d] = static_cast<int>(t);
  }
  const std::size_t cell = (static_cast<std::size_t>(idx[0]) * n_[1] + idx[1]) * n_[2] + idx[2];
  const int begin = start_[cell], end = start_[cell + 1];
  if (begin == end) return false;
  const Faces& F = topology_->faces();
  double best = std::numeric_limits<double>::infinity();
  int best_face = -1, best_feature = 6;
  Vec3 best_point = p;
  double best_norm = std::numeric_limits<double>::infinity();
  for (int s = begin; s < end; ++s) {
    const int f = faces_[s];
    const double reach = best_norm + radius_[f];
    if ((p - centroid_[f]).squaredNorm() >= reach * reach) continue;
    int feature = 6;
    const Vec3 q = closest_on_triangle(p, row(x_, F(f, 0)), row(x_, F(f, 1)), row(x_, F(f, 2)), feature);
    const double d2 = (p - q).squaredNorm();
    if (d2 < best) {
      best = d2;
      best_norm = std::sqrt(d2);
      best_face = f;
      best_feature = feature;
      best_point = q;
    }
  }
  const Vec3 n = pseudo_normal(best_face, best_feature);
  const double d = std::sqrt(best);
  const bool inside = (p - best_point).dot(n) < 0;
  if (!inside && d > band_) return false;
  hit.distance = inside ? -d : d;
  hit.closest = best_point;
  if (d > 1e-12 * (1 + best_point.norm())) {
    hit.outward = (inside ? -1.0 : 1.0) * (p - best_point) / d;
  } else {
    hit.outward = n.normalized();
  }
  return true;
}

namespace {

// Whether two oriented boxes (centre, axes as the columns of R, half extents) overlap: the 15
// separating axes of Gottschalk, Lin & Manocha (1996).
bool boxes_overlap(const Vec3& ca, const Mat3& Ra, const Vec3& ea, const Vec3& cb, const Mat3& Rb, const Vec3& eb) {
  const Mat3 R = Ra.transpose() * Rb;
  const Vec3 t = Ra.transpose() * (cb - ca);
  const Mat3 A = R.cwiseAbs().array() + 1e-12;
  for (int i = 0; i < 3; ++i) {
    if (std::abs(t[i]) > ea[i] + A.row(i).dot(eb)) return false;
  }
  for (int j = 0; j < 3; ++j) {
    if (std::abs(t.dot(R.col(j))) > ea.dot(A.col(j)) + eb[j]) return false;
  }
  for (int i = 0; i < 3; ++i) {
    const int i1 = (i + 1) % 3, i2 = (i + 2) % 3;
    for (int j = 0; j < 3; ++j) {
      const int j1 = (j + 1) % 3, j2 = (j + 2) % 3;
      const double ra = ea[i1] * A(i2, j) + ea[i2] * A(i1, j);
      const double rb = eb[j1] * A(i, j2) + eb[j2] * A(i, j1);
      if (std::abs(t[i2] * R(i1, j) - t[i1] * R(i2, j)) > ra + rb) return false;
    }
  }
  return true;
}

struct Push {
  Vec3 force = Vec3::Zero(), torque = Vec3::Zero();
  double r2 = 0;
  int count = 0;
  void add(const Vec3& arm, const Vec3& f) {
    force += f;
    torque += arm.cross(f);
    r2 += arm.squaredNorm();
    ++count;
  }
};

class Grower {
 public:
  Grower(const Vessel& vessel, const Topology& topology, const Points& reference, const GrowthOptions& o)
      : vessel_(vessel), reference_(reference), working_(o.clearance + o.margin), tol_(0.9 * o.margin),
        distance_(topology, reference, working_ / o.initial_scale) {
    for (Eigen::Index i = 0; i < reference.rows(); ++i) extent_ = std::max(extent_, reference.row(i).norm());
    const BoundingBox box = bounding_box(reference);
    box_middle_ = 0.5 * (box.lo + box.hi);
    box_half_ = 0.5 * (box.hi - box.lo);
    // Patches of vertices, bins about half the cell's radius wide, each with a bounding sphere:
    // a patch far from the other cell skips its vertices' queries.
    const double w = 0.5 * extent_;
    int nb[3];
    for (int d = 0; d < 3; ++d) nb[d] = std::max(1, static_cast<int>(std::ceil((box.hi[d] - box.lo[d]) / w)));
    std::vector<int> bin_of(reference.rows());
    std::vector<int> count(static_cast<std::size_t>(nb[0]) * nb[1] * nb[2], 0);
    for (Eigen::Index i = 0; i < reference.rows(); ++i) {
      int idx[3];
      for (int d = 0; d < 3; ++d) idx[d] = std::min(nb[d] - 1, static_cast<int>((reference(i, d) - box.lo[d]) / w));
      bin_of[i] = (idx[0] * nb[1] + idx[1]) * nb[2] + idx[2];
      ++count[bin_of[i]];
    }
    std::vector<int> patch_of_bin(count.size(), -1);
    for (std::size_t b = 0; b < count.size(); ++b) {
      if (count[b] == 0) continue;
      patch_of_bin[b] = static_cast<int>(patch_start_.size());
      patch_start_.push_back(0);
    }
    const int np = static_cast<int>(patch_start_.size());
    patch_start_.assign(np + 1, 0);
    for (Eigen::Index i = 0; i < reference.rows(); ++i) ++patch_start_[patch_of_bin[bin_of[i]] + 1];
    for (int q = 0; q < np; ++q) patch_start_[q + 1] += patch_start_[q];
    patch_vertex_.resize(reference.rows());
    std::vector<int> fill(patch_start_.begin(), patch_start_.end() - 1);
    for (Eigen::Index i = 0; i < reference.rows(); ++i) patch_vertex_[fill[patch_of_bin[bin_of[i]]]++] = static_cast<int>(i);
    patch_centre_.assign(np, Vec3::Zero());
    patch_radius_.assign(np, 0.0);
    for (int q = 0; q < np; ++q) {
      for (int k = patch_start_[q]; k < patch_start_[q + 1]; ++k) patch_centre_[q] += row(reference, patch_vertex_[k]);
      patch_centre_[q] /= patch_start_[q + 1] - patch_start_[q];
      for (int k = patch_start_[q]; k < patch_start_[q + 1]; ++k)
        patch_radius_[q] = std::max(patch_radius_[q], (row(reference, patch_vertex_[k]) - patch_centre_[q]).norm());
    }
  }

  // Sweeps at scale s until no overlap exceeds the tolerance (true) or `limit` sweeps are spent.
  bool relax(std::vector<PlacedCell>& cells, double s, std::int64_t limit) {
    const std::size_t n = cells.size();
    const Eigen::Index nv = reference_.rows();
    push_.resize(n);
    double best = std::numeric_limits<double>::infinity();
    std::int64_t best_sweep = 0;
    for (std::int64_t sweep = 0; sweep < limit; ++sweep) {
      ++sweeps_;
      world_.resize(static_cast<Eigen::Index>(n) * nv, 3);
      for (std::size_t c = 0; c < n; ++c) {
        world_.middleRows(static_cast<Eigen::Index>(c) * nv, nv) = (s * reference_) * cells[c].rotation.transpose();
        world_.middleRows(static_cast<Eigen::Index>(c) * nv, nv).rowwise() += cells[c].centre.transpose();
      }
      std::fill(push_.begin(), push_.end(), Push{});
      max_overlap_ = 0;
      for (std::size_t a = 0; a < n; ++a) {
        for (Eigen::Index i = 0; i < nv; ++i) {
          const Vec3 p = row(world_, static_cast<Eigen::Index>(a) * nv + i);
          const double w = vessel_.wall_distance(p);
          if (w >= working_) continue;
          const double o = working_ - w;
          max_overlap_ = std::max(max_overlap_, o);
          push_[a].add(p - cells[a].centre, o * vessel_.wall_normal(p));
        }
      }
      const Vec3 period = vessel_.period();
      const double reach = 2 * s * extent_ + working_;
      for (std::size_t a = 0; a < n; ++a) {
        for (std::size_t b = a; b < n; ++b) {
          const Vec3 sep = cells[b].centre - cells[a].centre;
          const Vec3 d0 = vessel_.minimum_image(sep) - sep;
          const int ny = vessel_.periodic(1) ? 1 : 0;
          for (int sx = -1; sx <= 1; ++sx) {
            for (int sy = -ny; sy <= ny; ++sy) {
              const Vec3 shift = d0 + Vec3(sx * period.x(), sy * period.y(), 0);
              // A cell and its own image: once, not again from the image's side.
              if (a == b && !(sx > 0 || (sx == 0 && sy > 0))) continue;
              if ((sep + shift).norm() > reach) continue;
              // Boxes in the cells' frames, each widened by half the working distance: apart,
              // no point of one is within that distance of the other.
              const Vec3 half = s * box_half_ + Vec3::Constant(0.5 * working_);
              if (!boxes_overlap(cells[a].centre + cells[a].rotation * (s * box_middle_), cells[a].rotation, half,
                                 cells[b].centre + shift + cells[b].rotation * (s * box_middle_), cells[b].rotation, half))
                continue;
              contacts(cells, s, a, b, shift);
              contacts(cells, s, b, a, -shift);
            }
          }
        }
      }
      if (max_overlap_ <= tol_) return true;
      // A step that has stopped getting anywhere is given up early.
      if (max_overlap_ < 0.99 * best) {
        best = max_overlap_;
        best_sweep = sweep;
      } else if (sweep - best_sweep >= kStall) {
        return false;
      }
      const double max_move = 0.1 * s * extent_;
      for (std::size_t c = 0; c < n; ++c) {
        const Push& q = push_[c];
        if (q.count == 0) continue;
        Vec3 t = q.force / q.count;
        if (t.norm() > max_move) t *= max_move / t.norm();
        const Vec3 theta = q.torque / q.r2;
        const double angle = std::min(theta.norm(), 0.1);
        cells[c].centre += t;
        if (angle > 0) {
          const Eigen::Quaterniond turn(Eigen::AngleAxisd(angle, theta.normalized()));
          cells[c].rotation = (turn * Eigen::Quaterniond(cells[c].rotation)).normalized().toRotationMatrix();
        }
      }
    }
    return false;
  }

  std::int64_t sweeps() const { return sweeps_; }

 private:
  // The vertices of cell a against the surface of cell b shifted by `shift`.
  void contacts(const std::vector<PlacedCell>& cells, double s, std::size_t a, std::size_t b, const Vec3& shift) {
    const Eigen::Index nv = reference_.rows();
    const Mat3& Rb = cells[b].rotation;
    const Vec3 cb = cells[b].centre + shift;
    // From a's frame into b's, both at scale s, in b's reference units.
    const Mat3 ab = Rb.transpose() * cells[a].rotation;
    const Vec3 shift_ab = Rb.transpose() * (cells[a].centre - cb) / s;
    MeshDistance::Hit hit;
    for (std::size_t patch = 0; patch < patch_centre_.size(); ++patch) {
      if (!distance_.near(ab * patch_centre_[patch] + shift_ab, patch_radius_[patch])) continue;
      for (int k = patch_start_[patch]; k < patch_start_[patch + 1]; ++k) {
        const Eigen::Index i = patch_vertex_[k];
        const Vec3 p = row(world_, static_cast<Eigen::Index>(a) * nv + i);
        const Vec3 q = ab * row(reference_, i) + shift_ab;
        if (!distance_.query(q, hit)) continue;
        const double o = working_ - s * hit.distance;
        if (o <= 0) continue;
        max_overlap_ = std::max(max_overlap_, o);
        const Vec3 f = o * (Rb * hit.outward);
        push_[a].add(p - cells[a].centre, f);
        push_[b].add(Rb * (s * hit.closest), -f);
      }
    }
  }

  static constexpr std::int64_t kStall = 60;
  const Vessel& vessel_;
  const Points& reference_;
  double working_, tol_, extent_ = 0;
  Vec3 box_middle_, box_half_;
  std::vector<int> patch_start_, patch_vertex_;
  std::vector<Vec3> patch_centre_;
  std::vector<double> patch_radius_;
  MeshDistance distance_;
  Points world_;
  std::vector<Push> push_;
  double max_overlap_ = 0;
  std::int64_t sweeps_ = 0;
};

}  // namespace

GrowthResult grow_cells(const Vessel& vessel, const Topology& topology, const Points& reference, std::vector<PlacedCell>& cells,
                        const GrowthOptions& o) {
  GrowthResult result;
  Grower grower(vessel, topology, reference, o);
  // First clear the cells at their initial scale (they keep the clearance between vertices, not
  // the working distance between surfaces), then grow.
  std::vector<PlacedCell> trial = cells;
  const bool cleared = grower.relax(trial, o.initial_scale, o.sweeps_per_step);
  result.sweeps = grower.sweeps();
  if (!cleared) return result;
  cells = trial;
  double s = o.initial_scale, step = 0.05;
  const double max_step = 0.05, min_step = 2.5e-3;
  while (s < 1) {
    const double next = std::min(1.0, s + step);
    trial = cells;
    const std::int64_t left = o.max_sweeps - grower.sweeps();
    if (left <= 0) break;
    const bool ok = grower.relax(trial, next, std::min<std::int64_t>(o.sweeps_per_step, left));
    if (ok) {
      cells = trial;
      s = next;
      step = std::min(1.5 * step, max_step);
    } else {
      step *= 0.5;
      if (step < min_step) break;
    }
  }
  result.scale = s;
  result.grown = s >= 1;
  result.sweeps = grower.sweeps();
  // Centres back into the period.
  const Vec3 period = vessel.period();
  for (PlacedCell& c : cells) {
    c.centre.x() -= period.x() * std::round(c.centre.x() / period.x());
    if (vessel.periodic(1)) c.centre.y() -= period.y() * std::round(c.centre.y() / period.y());
  }
  return result;
}

}  // namespace bendlab
