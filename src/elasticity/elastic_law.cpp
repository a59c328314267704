#include "bendlab/elasticity/elastic_law.hpp"

#include <fmt/format.h>

#include <cmath>

#include "bendlab/elasticity/neo_hookean.hpp"
#include "bendlab/elasticity/skalak.hpp"

namespace bendlab {

void flat_triangle_reference(const Topology& t, const Points& reference, const char* law, Scalars& a0, Scalars& m00,
                             Scalars& m01, Scalars& m11) {
  if (reference.rows() != t.num_vertices())
    throw Error(fmt::format("{}: {} reference positions for {} vertices", law, reference.rows(), t.num_vertices()));
  const int nf = t.num_faces();
  a0.resize(nf); m00.resize(nf); m01.resize(nf); m11.resize(nf);
  const Faces& F = t.faces();
  for (int f = 0; f < nf; ++f) {
    const Vec3 x0 = row(reference, F(f, 0));
    const Vec3 e1 = row(reference, F(f, 1)) - x0, e2 = row(reference, F(f, 2)) - x0;
    const double g00 = e1.dot(e1), g01 = e1.dot(e2), g11 = e2.dot(e2);
    const double det = g00 * g11 - g01 * g01;  // = (2 A0)^2
    if (!(det > 0)) throw Error(fmt::format("{}: reference triangle {} has zero area", law, f));
    a0[f] = 0.5 * std::sqrt(det);
    m00[f] = g11 / det;
    m01[f] = -g01 / det;
    m11[f] = g00 / det;
  }
}

void gather_corner_gradients(const Topology& t, const Points& grad1, const Points& grad2, Points& force) {
  const int nv = t.num_vertices();
  if (force.rows() != nv) force.resize(nv, 3);
  const auto& rf = t.ring_faces();
  const auto& rc = t.ring_corners();
#pragma omp parallel for schedule(static)
  for (int i = 0; i < nv; ++i) {
    Eigen::RowVector3d g = Eigen::RowVector3d::Zero();
    for (int k = t.ring_begin(i); k < t.ring_end(i); ++k) {
      const int f = rf[k];
      switch (rc[k]) {
        case 0: g -= grad1.row(f) + grad2.row(f); break;
        case 1: g += grad1.row(f); break;
        default: g += grad2.row(f); break;
      }
    }
    force.row(i) = -g;
  }
}

std::vector<std::string> elastic_law_names() { return {"neo-hookean", "skalak"}; }

std::unique_ptr<ElasticLaw> make_elastic_law(const std::string& name, TopologyPtr topology, const Points& reference,
                                             double kS, double skalak_c) {
  if (name == "neo-hookean") return std::make_unique<NeoHookean>(std::move(topology), reference, kS);
  if (name == "skalak") return std::make_unique<Skalak>(std::move(topology), reference, kS, skalak_c);
  throw Error(fmt::format("unknown elastic law '{}' (known: neo-hookean, skalak)", name));
}

}  // namespace bendlab
