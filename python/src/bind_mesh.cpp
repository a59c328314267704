// Meshes: validated triangle meshes, the paper's mesh families, files, geometry.
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include "arrays.hpp"
#include "bendlab/geometry/mesh_geometry.hpp"
#include "bendlab/mesh/generators.hpp"
#include "bendlab/mesh/mesh_io.hpp"
#include "bindings.hpp"

namespace bendlab::python {

void bind_mesh(py::module_& m) {
  py::class_<TriMesh>(m, "Mesh",
                      "A closed, oriented triangle mesh: vertices (N, 3) and counter-clockwise faces (F, 3), "
                      "validated on construction (docs/conventions.md §1). Meshes made from one another by "
                      "with_positions share their connectivity.")
      .def(py::init([](const py::handle& vertices, const py::handle& faces, bool flip_inward) {
             MeshOptions o;
             o.flip_inward = flip_inward;
             return TriMesh(points_from(vertices, "vertices"), faces_from(faces, "faces"), o);
           }),
           py::arg("vertices"), py::arg("faces"), py::arg("flip_inward") = false,
           "Validates the mesh (closed 2-manifold, one component, outward orientation, no degenerate "
           "triangle); raises ValueError naming the first problem. flip_inward reverses an inward mesh "
           "instead of refusing it.")
      .def_property_readonly("vertices", [](py::object self) { return view(self.cast<const TriMesh&>().positions(), self); },
                             "(N, 3) float64, read-only view")
      .def_property_readonly("faces", [](py::object self) { return view(self.cast<const TriMesh&>().faces(), self); },
                             "(F, 3) int32, read-only view")
      .def_property_readonly("num_vertices", &TriMesh::num_vertices)
      .def_property_readonly("num_faces", &TriMesh::num_faces)
      .def(
          "with_positions",
          [](const TriMesh& mesh, const py::handle& x) {
            Points p = points_from(x, "positions");
            if (p.rows() != mesh.num_vertices())
              throw py::value_error("positions: expected " + std::to_string(mesh.num_vertices()) + " rows, got " +
                                    std::to_string(p.rows()));
            return mesh.with_positions(std::move(p));
          },
          py::arg("positions"), "The same connectivity with new vertex positions (validated).")
      .def("__repr__", [](const TriMesh& t) {
        return "<bendlab.Mesh " + std::to_string(t.num_vertices()) + " vertices, " + std::to_string(t.num_faces()) +
               " triangles>";
      });

  m.def(
      "sphere_mesh",
      [](const std::string& family, int level, int rivara_passes) {
        return sphere_mesh(parse_mesh_family(family), level, rivara_passes);
      },
      py::arg("family") = "mt1", py::arg("level") = 3, py::arg("rivara_passes") = 0,
      "A unit-sphere mesh of the paper's families (docs/conventions.md §4): 'mt1' (icosahedron + Loop "
      "refinement), 'mt2' (midpoints), 'octa' or 'irregular' (MT1 with every node jittered tangentially "
      "by 0.25 of its mean edge length, seed 28 + level); level k (0..8) gives 20*4^k (8*4^k) triangles; "
      "rivara_passes (0..6) longest-edge bisection passes make the inhomogeneous meshes. The limits are bendlab "
      "mesh's.");
  m.def(
      "level_with_triangles",
      [](const std::string& family, long triangles) { return level_with_triangles(parse_mesh_family(family), triangles); },
      py::arg("family"), py::arg("triangles"), "The refinement level with that many triangles, or -1.");
  m.def("read_mesh", [](const std::filesystem::path& p) { return read_mesh(p); }, py::arg("path"),
        "Reads a .off, .obj or .ply file and validates it.");
  m.def(
      "write_mesh",
      [](const std::filesystem::path& path, const TriMesh& mesh, const py::dict& scalars, const py::dict& vectors) {
        VertexFields fields;
        for (auto [k, v] : scalars) {
          const py::array a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(v);
          if (!a || a.ndim() != 1) throw py::value_error("scalars: each field must be a 1-d array of numbers");
          fields.scalars.emplace_back(py::str(k), Eigen::Map<const Scalars>(static_cast<const double*>(a.data()), a.shape(0)));
        }
        for (auto [k, v] : vectors) fields.vectors.emplace_back(py::str(k), points_from(v, "vectors"));
        write_mesh(path, mesh.topology(), mesh.positions(), fields);
      },
      py::arg("path"), py::arg("mesh"), py::arg("scalars") = py::dict(), py::arg("vectors") = py::dict(),
      "Writes .off, .obj, .ply or .vtp (the last two with the named per-vertex fields); the file appears "
      "whole or not at all.");
  m.def(
      "geometry",
      [](const TriMesh& mesh) {
        MeshGeometry g = MeshGeometry::compute(mesh.topology(), mesh.positions());
        py::dict d;
        d["face_area"] = take(std::move(g.face_area));
        d["face_normal"] = take(std::move(g.face_normal));
        d["voronoi_area"] = take(std::move(g.voronoi_area));
        d["mixed_area"] = take(std::move(g.mixed_area));
        d["angle_sum"] = take(std::move(g.angle_sum));
        d["normal_mwa"] = take(std::move(g.normal_mwa));
        d["gaussian_curvature"] = take(std::move(g.gaussian_curvature));
        return d;
      },
      py::arg("mesh"),
      "Discrete geometry: face areas and normals, Voronoi (eq. 9) and Meyer's mixed areas, angle sums, "
      "mean-weighted-by-angle normals, angle-defect Gaussian curvature (eq. 12).");
}

}  // namespace bendlab::python
