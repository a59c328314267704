// Cells in a tube or a channel (bendlab flow): the library's FlowRun, so that a run started from
// Python resumes from the command line and the other way round.
#include <pybind11/functional.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <fmt/format.h>

#include <optional>

#include "bendlab/flow/flow_run.hpp"
#include "bindings.hpp"
#include "run_hooks.hpp"

namespace bendlab::python {

void bind_flow(py::module_& m) {
  m.def(
      "flow_run",
      [](const std::filesystem::path& folder, const std::string& geometry, std::optional<double> diameter,
         std::optional<double> height, std::optional<double> width, double length, double dx, double tau,
         std::optional<double> pseudo_shear_rate, std::optional<double> body_force, std::optional<double> shear_rate,
         std::optional<double> hematocrit,
         std::optional<int> cells, std::uint64_t seed, const std::string& cell, double cell_radius,
         const std::string& mesh, const std::string& method, const std::vector<std::string>& method_options,
         const std::optional<std::string>& bending_net_force, const std::string& membrane, double shear_modulus, double skalak_c, double bending_modulus,
         double volume_ratio, double contact_cutoff, double contact_force, double t_end, double sample_every,
         double snapshot_every, double steady_from, double slice_width, double time_scale, bool resume, bool overwrite,
         std::int64_t stop_after_steps, const py::object& progress, double progress_interval) -> py::object {
        if (geometry != "tube" && geometry != "channel" && geometry != "shear")
          throw Error(fmt::format("geometry '{}' is not tube, channel or shear", geometry));
        FlowRunSpec s;
        s.units.geometry = geometry == "tube"    ? lbm::FlowGeometry::Tube
                           : geometry == "shear" ? lbm::FlowGeometry::Shear
                                                 : lbm::FlowGeometry::Channel;
        s.units.diameter_um = diameter.value_or(0);
        s.units.height_um = height.value_or(0);
        s.units.width_um = width.value_or(0);
        s.units.length_um = length;
        s.units.dx_um = dx;
        s.units.tau = tau;
        s.units.time_scale = time_scale;
        s.units.pseudo_shear_rate = pseudo_shear_rate;
        s.units.body_force = body_force;
        s.units.shear_rate = shear_rate;
        s.hematocrit = hematocrit;
        s.cells = cells;
        if (!hematocrit && !cells) throw Error("give hematocrit (0: plain Poiseuille flow) or cells");
        s.seed = seed;
        s.cell.shape = cell;
        s.cell.radius_um = cell_radius;
        s.cell.mesh = mesh;
        s.cell.method = method;
        s.cell.method_options = method_options;
        s.cell.elastic_law = membrane;
        s.cell.shear_modulus = shear_modulus;
        s.cell.skalak_c = skalak_c;
        s.cell.bending_modulus = bending_modulus;
        s.cell.choose_bending_net_force(bending_net_force);  // as the flow command
        s.cell.volume_modulus_ratio = volume_ratio;
        s.contact_cutoff_um = contact_cutoff;
        s.contact_force = contact_force;
        s.sample_every = sample_every;
        s.steady_from = steady_from;
        s.slice_width_um = slice_width;
        FlowRun::check_end(s, t_end);  // before the relaxation

        RunHooks hooks(progress);
        CapsuleRunOptions o;
        o.folder = folder;
        o.t_end = t_end;
        o.snapshot_every = snapshot_every;
        o.resume = resume;
        o.overwrite = overwrite;
        o.stop_after_steps = stop_after_steps;
        o.progress_interval_seconds = progress_interval;
        o.should_stop = hooks.should_stop();
        o.on_progress = hooks.on_progress();
        CapsuleRunResult result;
        {
          py::gil_scoped_release release;
          FlowRun run(s);
          result = run.run(o);
        }
        hooks.rethrow();
        if (!result.finished) return py::none();
        return json_to_python(result.summary);
      },
      py::arg("folder"), py::arg("geometry") = "tube", py::arg("diameter") = py::none(),
      py::arg("height") = py::none(), py::arg("width") = py::none(), py::arg("length"), py::arg("dx") = 0.5,
      py::arg("tau") = 1.0, py::arg("pseudo_shear_rate") = py::none(), py::arg("body_force") = py::none(),
      py::arg("shear_rate") = py::none(), py::arg("hematocrit") = py::none(), py::arg("cells") = py::none(), py::arg("seed") = 1,
      py::arg("cell") = "rbc", py::arg("cell_radius") = 3.91, py::arg("mesh") = "mt1:1280", py::arg("method") = "C",
      py::arg("method_options") = std::vector<std::string>{}, py::arg("bending_net_force") = py::none(),
      py::arg("membrane") = "skalak",
      py::arg("shear_modulus") = 5.3e-6, py::arg("skalak_c") = 10.0, py::arg("bending_modulus") = 2e-19,
      py::arg("volume_ratio") = 100.0, py::arg("contact_cutoff") = 0.0, py::arg("contact_force") = 0.0,
      py::arg("t_end") = 0.01, py::arg("sample_every") = 1e-4, py::arg("snapshot_every") = 1e-3,
      py::arg("steady_from") = 0.5, py::arg("slice_width") = 1.0, py::arg("time_scale") = 1.0, py::arg("resume") = false,
      py::arg("overwrite") = false, py::arg("stop_after_steps") = 0, py::arg("progress") = py::none(),
      py::arg("progress_interval") = 2.0,
      "Runs cells in a tube (`diameter`), a slit channel or a shear box (`height`, `width`; the box driven by "
      "`shear_rate`), periodic over `length` (um), on the "
      "immersed-boundary lattice Boltzmann solver in physical units, as `bendlab flow` does (the same run folder: "
      "timeseries.csv, cells.csv, profiles.csv, snapshots, checkpoint.json, summary.json; see its --help for every "
      "option, here in snake case; contact_force in N, moduli in N/m and J, times in s). Returns summary.json's "
      "content, or None when stopped by stop_after_steps. progress(dict) is called every progress_interval seconds; "
      "Ctrl-C (or an exception in progress) stops the run at the next report, resumably (resume=True).");
}

}  // namespace bendlab::python
