// The capsule in shear flow (paper section 4): start or resume a run, read its time series and
// summary. The run is the library's run_shear, so a run started from Python resumes from the
// command line and the other way round.
#include <pybind11/functional.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <optional>

#include "arrays.hpp"
#include "bendlab/capsule/time_series.hpp"
#include "bendlab/core/file_input.hpp"
#include "bendlab/flow/shear_run.hpp"
#include "bindings.hpp"
#include "run_hooks.hpp"

namespace bendlab::python {

namespace {

std::string option_value(const py::handle& v) {
  if (py::isinstance<py::bool_>(v)) return v.cast<bool>() ? "true" : "false";
  return py::str(v);
}

}  // namespace

void bind_capsule(py::module_& m) {
  m.def(
      "shear_run",
      [](const std::filesystem::path& folder, const std::string& method, const std::string& mesh, double G,
         std::optional<double> kappa_b_hat, std::optional<double> kappa_b, double t_end, double snapshot_every,
         double rtol, double atol, bool resume, std::int64_t stop_after_steps, const py::object& progress,
         double progress_interval, const py::dict& method_options, const std::string& integrator,
         const std::string& membrane, double skalak_c, const std::string& bim_quadrature,
         bool overwrite, const std::string& shape, std::optional<double> aspect, double tilt,
         const std::string& reference_shape, std::optional<double> reference_aspect) -> py::object {
        ShearRunSpec spec;
        spec.folder = folder;
        spec.method = method;
        for (auto [k, v] : method_options) spec.method_options[py::str(k)] = option_value(v);
        spec.mesh = mesh;
        spec.shape.shape = shape;
        spec.shape.aspect = aspect;
        spec.shape.tilt_degrees = tilt;
        spec.shape.reference = reference_shape;
        spec.shape.reference_aspect = reference_aspect;
        spec.G = G;
        spec.kappa_b_hat = kappa_b_hat;
        spec.kappa_b = kappa_b;
        spec.t_end = t_end;
        spec.snapshot_every = snapshot_every;
        spec.integrator = integrator;
        spec.membrane = membrane;
        spec.skalak_c = skalak_c;
        spec.bim_quadrature = bim_quadrature;
        spec.rtol = rtol;
        spec.atol = atol;
        spec.resume = resume;
        spec.overwrite = overwrite;
        spec.stop_after_steps = stop_after_steps;

        RunHooks hooks(progress);
        ShearRunCallbacks cb;
        cb.progress_interval_seconds = progress_interval;
        cb.should_stop = hooks.should_stop();
        cb.on_progress = hooks.on_progress();
        CapsuleRunResult result;
        {
          py::gil_scoped_release release;
          result = run_shear(spec, cb);
        }
        hooks.rethrow();
        if (!result.finished) return py::none();
        return json_to_python(result.summary);
      },
      py::arg("folder"), py::arg("method") = "none", py::arg("mesh") = "mt1:1280", py::arg("G") = 0.1,
      py::arg("kappa_b_hat") = py::none(), py::arg("kappa_b") = py::none(), py::arg("t_end") = 10.0,
      py::arg("snapshot_every") = 0.5, py::arg("rtol") = 1e-7, py::arg("atol") = 1e-6, py::arg("resume") = false,
      py::arg("stop_after_steps") = 0, py::arg("progress") = py::none(), py::arg("progress_interval") = 2.0,
      py::arg("method_options") = py::dict(), py::arg("integrator") = "cash-karp",
      py::arg("membrane") = "neo-hookean", py::arg("skalak_c") = 1.0,
      py::arg("bim_quadrature") = "all7", py::arg("overwrite") = false, py::arg("shape") = "sphere",
      py::arg("aspect") = py::none(), py::arg("tilt") = 0.0, py::arg("reference_shape") = "initial",
      py::arg("reference_aspect") = py::none(),
      "Runs a capsule (initially the sphere, or `shape` 'rbc', 'oblate', 'prolate' of c/a `aspect` (None: 0.5, 2), its axis of "
      "symmetry tilted by `tilt` degrees from e_z towards e_x, stress-free in `reference_shape` ('initial' or a "
      "shape, of c/a `reference_aspect`), as `bendlab shear --shape` does; membrane law `membrane`: 'neo-hookean', eqs. 18-21, or 'skalak' "
      "with C = skalak_c; plus the bending method) in "
      "the shear flow u = gamma z e_x with the boundary integral method (eqs. 22-23), units R = mu = gamma "
      "= 1 (kS = 1/G, kB = kappa_b_hat / G), advanced by `integrator` ('cash-karp' or 'rkc'), the single layer's regular quadrature "
      "`bim_quadrature` (the reference 'all7', 'adaptive', 'tree' or 'tree-mixed'), until gamma t = t_end, keeping the run folder (timeseries.csv, "
      "snapshots, checkpoint.json, summary.json) exactly as `bendlab shear` does. progress(dict) is called "
      "every progress_interval seconds. Returns summary.json's content, or None when stopped by "
      "stop_after_steps. Ctrl-C (or an exception in progress) stops the run at the next step and is raised; "
      "the folder can then be resumed with resume=True. A folder holding another run is refused unless "
      "overwrite=True (which removes that run's files); a folder a running run owns is refused.");

  m.def(
      "read_time_series",
      [](const std::filesystem::path& folder) {
        const std::vector<TimeSeriesRow> rows = read_time_series(folder / "timeseries.csv");
        const auto n = static_cast<Eigen::Index>(rows.size());
        Scalars cols[10];
        for (Scalars& c : cols) c.resize(n);
        for (Eigen::Index i = 0; i < n; ++i) {
          const TimeSeriesRow& r = rows[static_cast<std::size_t>(i)];
          const double v[10] = {r.t, r.D, r.theta, r.volume, r.area, r.E_bend, r.E_elastic, r.dt, r.axis_angle,
                                r.node_phase};
          for (int k = 0; k < 10; ++k) cols[k][i] = v[k];
        }
        py::dict d;
        const char* names[10] = {"gamma_t", "D", "theta",  "volume",     "area",
                                 "E_bend",  "E_elastic", "dt", "axis_angle", "node_phase"};
        for (int k = 0; k < 10; ++k) d[names[k]] = take(std::move(cols[k]));
        return d;
      },
      py::arg("folder"), "The run's timeseries.csv as a dict of numpy arrays (gamma_t, D, theta, ...).");

  m.def(
      "read_summary",
      [](const std::filesystem::path& folder) {
        const std::filesystem::path p = folder / "summary.json";
        const std::string text = read_regular_file(p, "summary");
        nlohmann::json j = nlohmann::json::parse(text, nullptr, false);
        if (j.is_discarded()) throw Error("cannot read summary '" + p.string() + "': not valid JSON");
        return json_to_python(j);
      },
      py::arg("folder"), "The run's summary.json (D_steady, theta_steady, mean_gamma_dt, counters, ...).");
}

}  // namespace bendlab::python
