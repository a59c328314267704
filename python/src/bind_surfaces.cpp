// Analytic reference surfaces and the error measures of eq. (17).
#include <pybind11/stl.h>

#include <memory>

#include "arrays.hpp"
#include "bendlab/analysis/error_measures.hpp"
#include "bendlab/surfaces/analytic_surface.hpp"
#include "bindings.hpp"

namespace bendlab::python {

namespace {

py::dict fields_dict(SurfaceFields&& s) {
  py::dict d;
  d["normal"] = take(std::move(s.normal));
  d["H"] = take(std::move(s.H));
  d["K"] = take(std::move(s.K));
  d["lapH"] = take(std::move(s.lapH));
  d["f_normal"] = take(std::move(s.f_normal));
  d["f"] = take(std::move(s.f));
  return d;
}

Scalars scalars_from(const py::handle& obj, const char* name, Eigen::Index n) {
  if (!py::isinstance<py::array>(obj)) throw py::value_error(std::string(name) + ": expected a numpy array");
  const auto a = py::reinterpret_borrow<py::array>(obj);
  if (!a.dtype().is(py::dtype::of<double>()) || a.ndim() != 1 || a.shape(0) != n)
    throw py::value_error(std::string(name) + ": expected float64 of shape (" + std::to_string(n) + ",)");
  const auto c = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(a);
  return Eigen::Map<const Scalars>(c.data(), n);
}

}  // namespace

void bind_surfaces(py::module_& m) {
  py::class_<AnalyticSurface, std::shared_ptr<AnalyticSurface>>(
      m, "Surface",
      "An analytic surface of revolution about z (sphere, spheroid, the RBC of eq. 15) with its exact "
      "normal, H, K, Lap H and force density f (docs/conventions.md §1).")
      .def_property_readonly("name", &AnalyticSurface::name)
      .def(
          "evaluate",
          [](const AnalyticSurface& s, const py::handle& points, double kappa_b) {
            return fields_dict(s.evaluate(points_from(points, "points"), kappa_b));
          },
          py::arg("points"), py::arg("kappa_b") = 1.0,
          "Exact values at points on the surface: dict of normal, H, K, lapH, f_normal, f.")
      .def(
          "maxima",
          [](const AnalyticSurface& s, double kappa_b) {
            const SurfaceMaxima mx = s.maxima(kappa_b);
            return py::dict(py::arg("H") = mx.H, py::arg("K") = mx.K, py::arg("lapH") = mx.lapH, py::arg("f") = mx.f);
          },
          py::arg("kappa_b") = 1.0, "Maxima of |H|, |K|, |Lap H|, |f| over the surface: eq. (17)'s denominators.")
      .def(
          "map_from_unit_sphere",
          [](const AnalyticSurface& s, const py::handle& points) {
            return take(s.map_from_unit_sphere(points_from(points, "points")));
          },
          py::arg("points"), "Maps unit-sphere points onto the surface (the map of the mesh families).")
      .def(
          "require_on_surface",
          [](const AnalyticSurface& s, const py::handle& points, double tolerance) {
            require_nodes_on_surface(s, points_from(points, "points"), tolerance);
          },
          py::arg("points"), py::arg("relative_tolerance") = 1e-6,
          "Raises ValueError when a point lies farther than relative_tolerance * size from the surface.");

  m.def(
      "surface",
      [](const std::string& name, double radius, std::vector<double> axes) {
        return std::shared_ptr<AnalyticSurface>(make_surface(name, radius, std::move(axes)));
      },
      py::arg("name") = "rbc", py::arg("radius") = 1.0, py::arg("axes") = std::vector<double>{},
      "'sphere', 'rbc' (large half-axis radius), 'oblate', 'prolate' or 'spheroid' (axes a, c).");

  m.def(
      "node_errors",
      [](const AnalyticSurface& surface, const py::handle& points, const BendingResult& result, double kappa_b,
         double tolerance) {
        const Points x = points_from(points, "points");
        require_nodes_on_surface(surface, x, tolerance);
        const SurfaceFields exact = surface.evaluate(x, kappa_b);
        NodeErrors e = node_errors(exact, surface.maxima(kappa_b), result, kappa_b);
        py::dict d;
        for (Quantity q : kAllQuantities) {
          Scalars s = e[q];
          d[py::str(to_string(q))] = take(std::move(s));
        }
        return d;
      },
      py::arg("surface"), py::arg("points"), py::arg("result"), py::arg("kappa_b") = 1.0,
      py::arg("relative_tolerance") = 1e-6,
      "Per-node errors of eq. (17) (n, H, K, lapH, f) of a method's result at points on the surface; "
      "quantities the method does not define are NaN.");
  m.def(
      "summarize",
      [](const py::handle& errors) {
        const auto a = py::reinterpret_borrow<py::array>(errors);
        if (!py::isinstance<py::array>(errors) || a.ndim() != 1)
          throw py::value_error("errors: expected a 1-d numpy array");
        const ErrorSummary s = summarize(scalars_from(errors, "errors", a.shape(0)));
        return py::dict(py::arg("available") = s.available, py::arg("max") = s.max, py::arg("average") = s.average);
      },
      py::arg("errors"), "The maximum and plain average over the nodes (the study's two measures).");
}

}  // namespace bendlab::python
