#pragma once
// One step of 1-to-4 subdivision of a closed triangle mesh, as a refined topology and a sparse
// stencil S with x_fine = S x_coarse (no projection: the sphere generators project afterwards,
// generators.hpp).
//
// Refined topology: every face (a, b, c) becomes (a, m_ab, m_ca), (b, m_bc, m_ab), (c, m_ca, m_bc)
// and (m_ab, m_bc, m_ca), in this order, all with the parent's orientation. The old vertices keep
// their indices; the node on edge e is num_vertices + e, so new nodes follow the old ones in edge
// order (Topology::edge_vertices()).
//
// Loop's rules (Loop 1987): old vertex of valence d: (1 - d beta) v + beta sum(neighbours),
// beta = (5/8 - (3/8 + cos(2 pi / d) / 4)^2) / d; edge point: 3/8 (a + b) + 1/8 (c + d), c and d
// the vertices opposite the edge. Midpoint rule: old vertices stay, edge point (a + b) / 2.
#include <Eigen/SparseCore>

#include "bendlab/core/types.hpp"
#include "bendlab/mesh/topology.hpp"

namespace bendlab {

using SparseMatrix = Eigen::SparseMatrix<double, Eigen::RowMajor>;

struct SubdivisionStep {
  TopologyPtr topology;  ///< the refined connectivity
  SparseMatrix stencil;  ///< (V + E) x V: x_fine = stencil * x_coarse; every row sums to 1
};

/// The refined connectivity (1 -> 4 split, numbering above).
TopologyPtr split_in_four(const Topology& coarse);

/// Loop subdivision: refined topology and stencil.
SubdivisionStep loop_subdivision(const Topology& coarse);
/// Midpoint subdivision: refined topology and stencil.
SubdivisionStep midpoint_subdivision(const Topology& coarse);

/// The refined positions by Loop's rules, evaluated in factored form (beta times the sum of the
/// neighbours, 3/8 times a + b): what the mesh generators use. Equal to the stencil applied to x up
/// to rounding (the order of the floating-point operations differs).
Points loop_positions(const Topology& coarse, const Points& x);
/// The refined positions by the midpoint rule; bit-identical to midpoint_subdivision's stencil
/// applied to x (halving is exact).
Points midpoint_positions(const Topology& coarse, const Points& x);

}  // namespace bendlab
