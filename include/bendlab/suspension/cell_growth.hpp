#pragma once
// Rigid copies of one closed mesh grown in a vessel from a fraction of their size to full size
// without overlap: the dense path of cell placement (placement.hpp; docs/conventions.md §6).
//
// Every cell is the reference shape (vertex positions with the volume centroid at the origin)
// scaled by a common s, rotated and moved: x = s R X + c. The cells are first cleared at s0, then
// s rises towards 1 in steps of at most 0.05 and the cells are separated as rigid bodies after
// each. A contact is a vertex of one cell nearer than the working distance d = clearance + margin
// to the surface of another (its signed distance to the other's triangles, negative inside:
// MeshDistance) or to the wall; its overlap o = d - distance pushes the vertex's cell along the
// surface's outward normal and the other cell back at the nearest surface point. A sweep finds
// every contact, then moves each cell by its contacts' mean push (sum o n / their number, at most
// a tenth of its radius) and turns it by their torque over sum |r|^2 (at most 0.1 rad), all from
// the same contacts, in index order: the result depends on nothing but the input. Sweeps repeat
// until no overlap exceeds 0.9 margin, so every surface, and with it every vertex, keeps
// clearance + margin / 10; a step that does not get there within its sweeps, or gains less than
// 1 % on its largest overlap in 60 sweeps, is undone and halved (a step that succeeds is followed
// by one 1.5 times as long), and growth stops, not reached, when the step falls below 0.0025 or the
// sweeps run out. Periodic images, a cell's own included, count as other cells.
//
// Cost: pairs of cells whose boxes (in their own frames, widened by d / 2) do not overlap are
// skipped, and so are patches of a cell's vertices whose bounding ball misses the other cell's
// grid; a query then reads the triangles its grid cell keeps, nearest first.
#include <cstdint>
#include <vector>

#include "bendlab/core/types.hpp"
#include "bendlab/mesh/topology.hpp"
#include "bendlab/suspension/placement.hpp"
#include "bendlab/suspension/vessel.hpp"

namespace bendlab {

/// Signed distance from a point to one closed, outward-oriented triangle mesh, exact within
/// `band` of its surface and inside it: the nearest triangle (Ericson's regions), signed by the
/// angle-weighted pseudo-normal of the feature the nearest point lies on (Baerentzen & Aanaes
/// 2005), which tells inside from outside exactly on a closed mesh. A grid over the mesh's box
/// (widened by the band), cells half a mean edge wide, keeps per cell the triangles within
/// d(g) + 2e of its centre g (e half its diagonal), which hold the nearest triangle of any point
/// of the cell; a cell farther outside than band + e keeps none. The positions are copied; the
/// topology must outlive the object.
class MeshDistance {
 public:
  MeshDistance(const Topology& topology, const Points& x, double band);

  struct Hit {
    double distance = 0;  ///< signed: negative inside
    Vec3 closest = Vec3::Zero();
    Vec3 outward = Vec3::Zero();  ///< unit: from the surface towards p outside, from p towards the surface inside
  };
  /// Whether p lies inside the mesh or within `band` of it (then `hit` holds its distance).
  bool query(const Vec3& p, Hit& hit) const;
  double band() const { return band_; }
  /// Whether a ball reaches the grid's box (else none of its points is within the band).
  bool near(const Vec3& centre, double radius) const;

 private:
  // The angle-weighted pseudo-normal of a face's corner (0..2), edge opposite a corner (3..5) or
  // interior (6): its sign tells inside from outside at the nearest point.
  Vec3 pseudo_normal(int face, int feature) const;
  const Topology* topology_;
  Points x_;
  std::vector<Vec3> face_normal_, edge_normal_, vertex_normal_, centroid_;
  std::vector<double> radius_;  ///< of each triangle about its centroid
  double band_, h_, inv_h_ = 1;
  Vec3 lo_;
  int n_[3] = {0, 0, 0};
  std::vector<int> start_, faces_;
};

struct GrowthOptions {
  double clearance = 0;
  double margin = 0;           ///< kept beyond the clearance while relaxing
  double initial_scale = 0.6;  ///< the cells' scale as given
  int sweeps_per_step = 300;   ///< at most, before a step is undone and halved
  std::int64_t max_sweeps = 20000;
};

struct GrowthResult {
  bool grown = false;  ///< reached scale 1 with no overlap beyond margin / 2
  double scale = 0;    ///< the largest scale reached without overlap
  std::int64_t sweeps = 0;
};

/// Grows `cells` (each at options.initial_scale, clear of each other) to full size, moving and
/// turning them; on return they hold the configuration at result.scale.
GrowthResult grow_cells(const Vessel& vessel, const Topology& topology, const Points& reference,
                        std::vector<PlacedCell>& cells, const GrowthOptions& options);

}  // namespace bendlab
