#include "bendlab/mesh/enclosed_volume.hpp"

namespace bendlab {

double enclosed_volume(const Topology& t, const Points& x) {
  const Faces& F = t.faces();
  double v = 0;
  for (int f = 0; f < t.num_faces(); ++f) {
    const Vec3 a = x.row(F(f, 0)), b = x.row(F(f, 1)), c = x.row(F(f, 2));
    v += a.dot(b.cross(c));
  }
  return v / 6.0;
}

}  // namespace bendlab
