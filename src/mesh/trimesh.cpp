#include "bendlab/mesh/trimesh.hpp"

#include <fmt/format.h>

#include <cmath>
#include <numeric>
#include <vector>

#include "bendlab/mesh/enclosed_volume.hpp"

namespace bendlab {

void validate_geometry(const Topology& topology, const Points& x) {
  if (x.rows() != topology.num_vertices())
    throw Error(fmt::format("{} positions given for {} vertices", x.rows(), topology.num_vertices()));
  for (Eigen::Index i = 0; i < x.rows(); ++i)
    if (!x.row(i).allFinite())
      throw MeshError(MeshProblem::NonFinite,
                      fmt::format("vertex {} has coordinates ({}, {}, {})", i, x(i, 0), x(i, 1), x(i, 2)));
  // Areas scale with the square and volumes with the cube of the coordinates, and the squared norms
  // of area vectors with the fourth power (1e60^4 = 1e240, leaving room for the moduli): outside these bounds
  // they over- or underflow double precision and later checks would misname the problem.
  constexpr double kLargestCoordinate = 1e60, kSmallestExtent = 1e-60;
  if (x.rows() > 0) {
    const double largest = x.cwiseAbs().maxCoeff();
    const double extent = (x.colwise().maxCoeff() - x.colwise().minCoeff()).maxCoeff();
    if (largest > kLargestCoordinate)
      throw MeshError(MeshProblem::OutOfRange,
                      fmt::format("the largest coordinate magnitude {:.3g} exceeds {:.0e}, where areas and volumes "
                                  "overflow: rescale the mesh",
                                  largest, kLargestCoordinate));
    if (extent < kSmallestExtent)
      throw MeshError(MeshProblem::OutOfRange,
                      fmt::format("the mesh extends only {:.3g} (below {:.0e}), where areas and volumes underflow: "
                                  "rescale the mesh",
                                  extent, kSmallestExtent));
  }
  const Faces& F = topology.faces();
  for (int f = 0; f < topology.num_faces(); ++f) {
    const Vec3 a = x.row(F(f, 0)), b = x.row(F(f, 1)), c = x.row(F(f, 2));
    const double longest2 = std::max({(b - a).squaredNorm(), (c - b).squaredNorm(), (a - c).squaredNorm()});
    // Twice the area against the square of the longest edge: a scale-free sliver measure.
    if ((b - a).cross(c - a).norm() <= 1e-12 * longest2)
      throw MeshError(MeshProblem::ZeroArea,
                      fmt::format("face {} = ({}, {}, {}) has zero area", f, F(f, 0), F(f, 1), F(f, 2)));
  }
}

namespace {

// One closed surface: every face reachable from face 0 across edges. Two disjoint spheres pass
// every other check, and would give a capsule's shape measures of a body that does not exist.
// Both constructors check it (a mesh is one component, as Topology::build's checks are local).
void check_connected(const Topology& topology) {
  const int nf = topology.num_faces();
  std::vector<int> parent(static_cast<std::size_t>(nf));
  std::iota(parent.begin(), parent.end(), 0);
  auto root = [&](int f) {
    while (parent[f] != f) f = parent[f] = parent[parent[f]];
    return f;
  };
  const auto& ef = topology.edge_faces();
  for (Eigen::Index e = 0; e < ef.rows(); ++e) parent[root(ef(e, 0))] = root(ef(e, 1));
  int components = 0, other = -1;
  for (int f = 0; f < nf; ++f)
    if (root(f) == f) {
      ++components;
      if (root(0) != f) other = f;
    }
  if (components > 1)
    throw Error(fmt::format("several components: the mesh has {} connected components (face {} is not connected "
                            "to face 0); it must be one closed surface",
                            components, other));
}

void check_outward(const Topology& topology, const Points& x) {
  const double v = enclosed_volume(topology, x);
  if (!(v > 0))
    throw MeshError(MeshProblem::InwardOrientation,
                    fmt::format("enclosed volume {} is not positive: the faces are clockwise seen from "
                                "outside (reverse them, or use the flip option)", v));
}

}  // namespace

TriMesh::TriMesh(Points positions, const Faces& faces, MeshOptions options)
    : topology_(Topology::build(static_cast<int>(positions.rows()), faces)), positions_(std::move(positions)) {
  validate_geometry(*topology_, positions_);
  check_connected(*topology_);
  if (options.flip_inward && enclosed_volume(*topology_, positions_) < 0) {
    Faces flipped = faces;
    flipped.col(1).swap(flipped.col(2));
    topology_ = Topology::build(static_cast<int>(positions_.rows()), flipped);
  }
  check_outward(*topology_, positions_);
}

TriMesh::TriMesh(TopologyPtr topology, Points positions)
    : topology_(std::move(topology)), positions_(std::move(positions)) {
  validate_geometry(*topology_, positions_);
  check_connected(*topology_);
  check_outward(*topology_, positions_);
}

}  // namespace bendlab
