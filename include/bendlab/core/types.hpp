#pragma once
// Plain array types shared by every module. Per-vertex data are N-row arrays, row-major so
// that an N x 3 block has the memory layout of a numpy (N, 3) array of float64.
#include <Eigen/Dense>
#include <limits>
#include <stdexcept>
#include <string>

namespace bendlab {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
/// N x 3 positions, forces, normals, force densities (row i = vertex i).
using Points = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;
/// F x 3 vertex indices of the triangles, counter-clockwise seen from outside.
using Faces = Eigen::Matrix<int, Eigen::Dynamic, 3, Eigen::RowMajor>;
/// E x 2 integer pairs (edge endpoints, edge faces, ...).
using IndexPairs = Eigen::Matrix<int, Eigen::Dynamic, 2, Eigen::RowMajor>;
/// N per-vertex (or per-face, per-edge) scalars.
using Scalars = Eigen::VectorXd;

inline Vec3 row(const Points& p, Eigen::Index i) { return p.row(i).transpose(); }

/// The value of a quantity that is not defined (a measure with no data, an unset field).
inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// Every error bendlab reports to a user: a one-line message naming the problem.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace bendlab
