#include "bendlab/mesh/subdivision.hpp"

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

namespace bendlab {

namespace {

/// Loop's beta for a vertex of valence d.
double loop_beta(int d) {
  const double c = 3.0 / 8.0 + std::cos(2.0 * std::numbers::pi / d) / 4.0;
  return (5.0 / 8.0 - c * c) / d;
}

SparseMatrix from_triplets(int rows, int cols, const std::vector<Eigen::Triplet<double>>& triplets) {
  SparseMatrix s(rows, cols);
  s.setFromTriplets(triplets.begin(), triplets.end());
  return s;
}

}  // namespace

TopologyPtr split_in_four(const Topology& t) {
  const int n = t.num_vertices();
  const Faces& f = t.faces();
  const Faces& fe = t.face_edges();
  Faces out(4 * f.rows(), 3);
  for (Eigen::Index i = 0; i < f.rows(); ++i) {
    const int a = f(i, 0), b = f(i, 1), c = f(i, 2);
    // face_edges(i, k) is opposite corner k.
    const int m_bc = n + fe(i, 0), m_ca = n + fe(i, 1), m_ab = n + fe(i, 2);
    out.row(4 * i + 0) << a, m_ab, m_ca;
    out.row(4 * i + 1) << b, m_bc, m_ab;
    out.row(4 * i + 2) << c, m_ca, m_bc;
    out.row(4 * i + 3) << m_ab, m_bc, m_ca;
  }
  return Topology::build(n + t.num_edges(), out);
}

SubdivisionStep loop_subdivision(const Topology& t) {
  const int n = t.num_vertices(), ne = t.num_edges();
  std::vector<Eigen::Triplet<double>> w;
  w.reserve(t.ring_vertices().size() + n + 4 * static_cast<std::size_t>(ne));
  for (int i = 0; i < n; ++i) {
    const int d = t.valence(i);
    const double beta = loop_beta(d);
    w.emplace_back(i, i, 1.0 - d * beta);
    for (int k = t.ring_begin(i); k < t.ring_end(i); ++k) w.emplace_back(i, t.ring_vertices()[k], beta);
  }
  const IndexPairs& ev = t.edge_vertices();
  const IndexPairs& eo = t.edge_opposite();
  for (int e = 0; e < ne; ++e) {
    w.emplace_back(n + e, ev(e, 0), 3.0 / 8.0);
    w.emplace_back(n + e, ev(e, 1), 3.0 / 8.0);
    w.emplace_back(n + e, eo(e, 0), 1.0 / 8.0);
    w.emplace_back(n + e, eo(e, 1), 1.0 / 8.0);
  }
  return {split_in_four(t), from_triplets(n + ne, n, w)};
}

SubdivisionStep midpoint_subdivision(const Topology& t) {
  const int n = t.num_vertices(), ne = t.num_edges();
  std::vector<Eigen::Triplet<double>> w;
  w.reserve(n + 2 * static_cast<std::size_t>(ne));
  for (int i = 0; i < n; ++i) w.emplace_back(i, i, 1.0);
  const IndexPairs& ev = t.edge_vertices();
  for (int e = 0; e < ne; ++e) {
    w.emplace_back(n + e, ev(e, 0), 0.5);
    w.emplace_back(n + e, ev(e, 1), 0.5);
  }
  return {split_in_four(t), from_triplets(n + ne, n, w)};
}

Points loop_positions(const Topology& t, const Points& x) {
  if (x.rows() != t.num_vertices())
    throw Error("loop_positions: " + std::to_string(x.rows()) + " positions for " +
                std::to_string(t.num_vertices()) + " vertices");
  const int n = t.num_vertices(), ne = t.num_edges();
  Points y(n + ne, 3);
  for (int i = 0; i < n; ++i) {
    const int d = t.valence(i);
    const double beta = loop_beta(d);
    Vec3 sum = Vec3::Zero();
    for (int k = t.ring_begin(i); k < t.ring_end(i); ++k) sum += row(x, t.ring_vertices()[k]);
    y.row(i) = ((1.0 - d * beta) * row(x, i) + beta * sum).transpose();
  }
  const IndexPairs& ev = t.edge_vertices();
  const IndexPairs& eo = t.edge_opposite();
  for (int e = 0; e < ne; ++e) {
    y.row(n + e) = 3.0 / 8.0 * (x.row(ev(e, 0)) + x.row(ev(e, 1))) + 1.0 / 8.0 * (x.row(eo(e, 0)) + x.row(eo(e, 1)));
  }
  return y;
}

Points midpoint_positions(const Topology& t, const Points& x) {
  if (x.rows() != t.num_vertices())
    throw Error("midpoint_positions: " + std::to_string(x.rows()) + " positions for " +
                std::to_string(t.num_vertices()) + " vertices");
  const int n = t.num_vertices(), ne = t.num_edges();
  Points y(n + ne, 3);
  y.topRows(n) = x;
  const IndexPairs& ev = t.edge_vertices();
  for (int e = 0; e < ne; ++e) y.row(n + e) = 0.5 * (x.row(ev(e, 0)) + x.row(ev(e, 1)));
  return y;
}

}  // namespace bendlab
