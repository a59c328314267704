// Bending forces of every method on the analytic red blood cell, from an installed bendlab.
// Prints, per method, the largest node force and the average error of the force density
// against the exact surface (eq. 17), on the 1280-triangle MT1 mesh mapped onto the RBC.
#include <bendlab/analysis/error_measures.hpp>
#include <bendlab/bending/bending_method.hpp>
#include <bendlab/bending/method_registry.hpp>

#include <string>
#include <bendlab/mesh/generators.hpp>
#include <bendlab/surfaces/analytic_surface.hpp>

#include <cstdio>

int main() {
  using namespace bendlab;
  const auto rbc = make_rbc(1.0);
  const TriMesh sphere = sphere_mesh(MeshFamily::MT1, 3);
  const TriMesh mesh = sphere.with_positions(rbc->map_from_unit_sphere(sphere.positions()));
  const SurfaceFields exact = rbc->evaluate(mesh.positions());
  std::printf("%-3s %14s %14s\n", "", "max |F|", "avg eps_f");
  for (const std::string& name : bending_method_names()) {
    const auto method = make_bending_method(name);
    const BendingResult r = method->compute(mesh.topology(), mesh.positions(), 1.0);
    const NodeErrors e = node_errors(exact, rbc->maxima(), r);
    std::printf("%-3s %14.6g %14.6g\n", name.c_str(), r.force.rowwise().norm().maxCoeff(), summarize(e.f).average);
  }
  return 0;
}
