// Bending methods: every registered method with its options, and its per-vertex results.
#include <pybind11/stl.h>

#include <chrono>
#include <memory>

#include "arrays.hpp"
#include "bendlab/bending/bending_method.hpp"
#include "bendlab/bending/method_registry.hpp"
#include "bendlab/bending/result_check.hpp"
#include "bendlab/core/finite_check.hpp"
#include "bendlab/mesh/trimesh.hpp"
#include "bindings.hpp"

namespace bendlab::python {

namespace {

/// Method options as the command line spells them: every value becomes a string (True -> "true").
MethodOptions options_from(const py::dict& kwargs) {
  MethodOptions o;
  for (auto [k, v] : kwargs) {
    std::string value;
    if (py::isinstance<py::bool_>(v)) value = v.cast<bool>() ? "true" : "false";
    else value = py::str(v);
    o[py::str(k)] = value;
  }
  return o;
}

// The command line's checks (bendlab forces), word for word: a finite kappa_b >= 0 before the work,
// and a result without NaN or infinity after it (kappa_b = 1e308 overflows the forces).
void require_kappa(double kappa_b) { require_positive("kappa_b", kappa_b, true); }

/// A method with the options it was made with (methods are immutable and may be shared).
struct PyMethod {
  std::shared_ptr<const BendingMethod> method;
  BendingParameters terms;  ///< c0 and ADE (docs/conventions.md §5); its kappa_b is replaced per call
  BendingParameters with(double kappa_b) const {
    BendingParameters p = terms;
    p.kappa_b = kappa_b;
    return p;
  }
};

/// Takes c0, ade_alpha, ade_d, ade_da0, ade_area out of the keyword arguments.
BendingParameters terms_from(py::dict& kwargs) {
  BendingParameters p;
  auto take_real = [&](const char* key, double& v) {
    if (!kwargs.contains(key)) return;
    const py::object value = kwargs[key];
    // pybind11's own message ("Unable to cast Python instance to C++ type") names no argument.
    try {
      v = value.cast<double>();
    } catch (const py::cast_error&) {
      throw py::type_error(std::string("Method: ") + key + " must be a real number, got " +
                           py::repr(value).cast<std::string>() + " (" +
                           py::str(py::type::handle_of(value).attr("__name__")).cast<std::string>() + ")");
    }
    PyDict_DelItemString(kwargs.ptr(), key);
  };
  take_real("c0", p.c0);
  take_real("ade_alpha", p.ade_alpha);
  take_real("ade_d", p.ade_d);
  take_real("ade_da0", p.ade_da0);
  take_real("ade_area", p.ade_area);
  if (!p.has_ade() && (p.ade_d != 0 || p.ade_da0 != 0 || p.ade_area != 0))
    throw Error("ade_d, ade_da0 and ade_area need ade_alpha > 0");
  if (p.has_ade() && p.ade_area == 0) throw Error("ade_alpha needs ade_area (the membrane area A of the ADE coefficient)");
  return p;
}

}  // namespace

void bind_bending(py::module_& m) {
  m.def(
      "methods",
      [] {
        py::list out;
        for (const MethodInfo& info : bending_methods()) {
          py::list options;
          for (const OptionSpec& o : info.options) {
            py::dict d(py::arg("name") = o.name, py::arg("type") = to_string(o.type),
                       py::arg("default") = o.default_value, py::arg("help") = o.help);
            if (o.type == OptionType::Int || o.type == OptionType::Real) d["range"] = py::make_tuple(o.min, o.max);
            if (o.type == OptionType::Choice) d["choices"] = o.choices;
            options.append(d);
          }
          const MethodCapabilities& c = info.capabilities;
          py::dict caps(py::arg("has_energy") = c.has_energy, py::arg("defines_normal") = c.defines_normal,
                        py::arg("defines_H") = c.defines_H, py::arg("defines_K") = c.defines_K,
                        py::arg("defines_lapH") = c.defines_lapH,
                        py::arg("needs_admissible_mesh") = c.needs_admissible_mesh, py::arg("cost") = c.cost);
          out.append(py::dict(py::arg("name") = info.name, py::arg("description") = info.description,
                              py::arg("options") = options, py::arg("capabilities") = caps));
        }
        return out;
      },
      "Every registered bending method: name, description, options (name, type, default, range or "
      "choices, help) and capabilities -- the same table as `bendlab methods --json`.");

  py::class_<BendingResult>(m, "BendingResult",
                            "Per-vertex results of one bending method (docs/conventions.md §1). Arrays are "
                            "read-only views of the result; quantities the method does not define are NaN.")
      .def_property_readonly("normal", [](py::object s) { return view(s.cast<const BendingResult&>().normal, s); },
                             "(N, 3) unit outward normal the method uses")
      .def_property_readonly("H", [](py::object s) { return view(s.cast<const BendingResult&>().H, s); },
                             "(N,) mean curvature, H > 0 on a sphere")
      .def_property_readonly("K", [](py::object s) { return view(s.cast<const BendingResult&>().K, s); },
                             "(N,) Gaussian curvature")
      .def_property_readonly("lapH", [](py::object s) { return view(s.cast<const BendingResult&>().lapH, s); },
                             "(N,) Laplace-Beltrami of H (div grad)")
      .def_property_readonly("force", [](py::object s) { return view(s.cast<const BendingResult&>().force, s); },
                             "(N, 3) node force F (eq. 14: F = f A_mixed)")
      .def_property_readonly("force_density",
                             [](py::object s) { return view(s.cast<const BendingResult&>().force_density, s); },
                             "(N, 3) force density f = 2 kB (Lap H + 2 H (H^2 - K)) n (eq. 10)")
      .def_property_readonly("area", [](py::object s) { return view(s.cast<const BendingResult&>().area, s); },
                             "(N,) Meyer's mixed area used for F <-> f")
      .def_property_readonly("energy", [](const BendingResult& r) { return r.energy; },
                             "bending energy E_B for energy-based methods, else None");

  py::class_<PyMethod>(m, "Method",
                       "A bending method of the paper (A Kantor-Nelson, B Gompper-Kroll, C Meyer, D Belkin, "
                       "E Farutin, ED, S Loop shell, J Juelicher, M Monge jet) with its options, e.g. Method('E', rings=2). "
                       "bendlab.methods() lists them. Membrane parameters (docs/conventions.md §5): c0 (spontaneous "
                       "curvature), ade_alpha, ade_d, ade_da0, ade_area (area-difference elasticity), e.g. "
                       "Method('C', c0=1.0); defaults give the paper's energy. Method A refuses c0 and ADE.")
      .def(py::init([](const std::string& name, const py::kwargs& kwargs) {
             py::dict options(kwargs);  // a copy: the membrane parameters are taken out of it
             const BendingParameters terms = terms_from(options);
             PyMethod p{std::shared_ptr<const BendingMethod>(make_bending_method(name, options_from(options))), terms};
             p.method->check_parameters(terms);
             return p;
           }),
           py::arg("name"))
      .def_property_readonly("name", [](const PyMethod& p) { return p.method->name(); })
      .def(
          "compute",
          [](const PyMethod& p, const TriMesh& mesh, double kappa_b) {
            require_kappa(kappa_b);
            py::gil_scoped_release release;
            BendingResult r = p.terms.plain() ? p.method->compute(mesh.topology(), mesh.positions(), kappa_b)
                                              : p.method->compute(mesh.topology(), mesh.positions(), p.with(kappa_b));
            require_finite_result(r, p.method->name());
            return r;
          },
          py::arg("mesh"), py::arg("kappa_b") = 1.0,
          "Every per-vertex quantity: normal, H, K, lapH, force, force_density, area, energy.")
      .def(
          "forces",
          [](const PyMethod& p, const TriMesh& mesh, double kappa_b) {
            require_kappa(kappa_b);
            Points f;
            {
              py::gil_scoped_release release;
              if (p.terms.plain())
                p.method->forces(mesh.topology(), mesh.positions(), kappa_b, f);
              else
                p.method->forces(mesh.topology(), mesh.positions(), p.with(kappa_b), f);
            }
            require_finite_rows(f, "method " + p.method->name() + ": F");
            return take(std::move(f));
          },
          py::arg("mesh"), py::arg("kappa_b") = 1.0, "Node forces F, (N, 3): what a flow solver needs.")
      .def(
          "energy",
          [](const PyMethod& p, const TriMesh& mesh, double kappa_b) {
            require_kappa(kappa_b);
            if (p.terms.plain()) return p.method->energy(mesh.topology(), mesh.positions(), kappa_b);
            return p.method->energy(mesh.topology(), mesh.positions(), p.with(kappa_b));
          },
          py::arg("mesh"), py::arg("kappa_b") = 1.0, "E_B for energy-based methods (A, B, S), else None.")
      .def("__repr__", [](const PyMethod& p) { return "<bendlab.Method " + p.method->name() + ">"; })
      .def(
          "_seconds_per_compute_in_cpp",
          [](const PyMethod& p, const TriMesh& mesh, double kappa_b, int repeats) {
            // For scripts/bench_python.py: the same call timed inside C++, to measure what the
            // binding layer adds. Not part of the API.
            py::gil_scoped_release release;
            const auto t0 = std::chrono::steady_clock::now();
            for (int k = 0; k < repeats; ++k) {
              const BendingResult r = p.method->compute(mesh.topology(), mesh.positions(), kappa_b);
              if (r.force.rows() != mesh.num_vertices()) throw Error("unexpected result size");
            }
            return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() / repeats;
          },
          py::arg("mesh"), py::arg("kappa_b") = 1.0, py::arg("repeats") = 100);
}

}  // namespace bendlab::python
