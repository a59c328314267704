#include "bendlab/mesh/trimesh.hpp"

#include <fmt/format.h>

#include <cmath>

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
  check_outward(*topology_, positions_);
}

}  // namespace bendlab
