#pragma once
// What the tests of the single layer's rules share (tests/flow/test_stokes_single_layer.cpp and
// test_single_layer_{adaptive,tree,mixed}.cpp): the shapes and density of the comparison, the
// relative difference, and the tree's check against all7.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "bendlab/bending/bending_method.hpp"
#include "bendlab/flow/bim/stokes_single_layer.hpp"
#include "bendlab/mesh/generators.hpp"
#include "bendlab/surfaces/analytic_surface.hpp"

namespace bendlab::test_support {

// The shapes of the quadrature comparison: the red blood cell of eq. (15) and the 2:1:0.5
// ellipsoid, mapped from the MT1 sphere; force density = Method C's bending force density (kB = 1).
struct Case {
  TriMesh sphere;
  Points x, f;
};

inline Case quadrature_case(int triangles, bool rbc) {
  Case c{sphere_mesh(MeshFamily::MT1, level_with_triangles(MeshFamily::MT1, triangles)), {}, {}};
  c.x = c.sphere.positions();
  if (rbc) {
    c.x = make_rbc(1.0)->map_from_unit_sphere(c.x);
  } else {
    c.x.col(0) *= 2.0;
    c.x.col(2) *= 0.5;
  }
  c.f = make_bending_method("C")->compute(c.sphere.topology(), c.x, 1.0).force_density;
  return c;
}

// max_i |u(x_i) - u_ref(x_i)| / max_i |u_ref(x_i)|.
inline double relative_difference(const Points& u, const Points& u_ref) {
  return (u - u_ref).rowwise().norm().maxCoeff() / u_ref.rowwise().norm().maxCoeff();
}

inline Points single_layer(const Case& c, SingleLayerOptions o) {
  Points u;
  StokesSingleLayer(c.sphere.topology_ptr(), o).velocity(c.x, c.f, 1.0, u);
  return u;
}

inline SingleLayerOptions with(SingleLayerQuadrature q, double far_ratio = SingleLayerOptions{}.far_ratio,
                        int far_order = SingleLayerOptions{}.far_order) {
  SingleLayerOptions o;
  o.quadrature = q;
  o.far_ratio = far_ratio;
  o.far_order = far_order;
  return o;
}

inline std::string scientific(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.2e", v);
  return buffer;
}

inline SingleLayerOptions tree_rule(double tolerance = SingleLayerOptions{}.tree_tolerance,
                             double ratio = SingleLayerOptions{}.tree_ratio,
                             SingleLayerQuadrature quadrature = SingleLayerQuadrature::tree) {
  SingleLayerOptions o;
  o.quadrature = quadrature;
  o.tree_tolerance = tolerance;
  o.tree_ratio = ratio;
  return o;
}

// max_i |u_tree - u_all7| / max_i |u_all7| on both shapes below the spec's 1e-5, and the far
// field used (the difference is not at rounding level).
inline void expect_tree_within_1e5(int triangles, SingleLayerQuadrature quadrature = SingleLayerQuadrature::tree) {
  const SingleLayerOptions rule = tree_rule(SingleLayerOptions{}.tree_tolerance, SingleLayerOptions{}.tree_ratio, quadrature);
  for (bool rbc : {true, false}) {
    const Case c = quadrature_case(triangles, rbc);
    const double e = relative_difference(single_layer(c, rule), single_layer(c, with(SingleLayerQuadrature::all7)));
    ::testing::Test::RecordProperty(rbc ? "rbc" : "ellipsoid", scientific(e));
    const std::string what = std::string(rbc ? "red blood cell" : "ellipsoid 2:1:0.5") + ", " +
                             std::to_string(triangles) + " triangles";
    EXPECT_LT(e, 1e-5) << what;
    EXPECT_GT(e, 1e-12) << what << ": the far field was not used";
  }
}

}  // namespace bendlab::test_support
