#pragma once
// What a run started from Python shares with the interpreter (shear_run, flow_run): progress(dict)
// every interval, and Ctrl-C or an exception raised in progress stop the run at the next step
// (resumable from its last checkpoint) and are raised again once the run has returned.
#include <pybind11/pybind11.h>

#include <functional>
#include <optional>

#include "bendlab/capsule/capsule_run.hpp"

namespace bendlab::python {

namespace py = pybind11;

/// A summary (JSON) as Python objects.
inline py::object json_to_python(const nlohmann::json& j) {
  return py::module_::import("json").attr("loads")(j.dump());
}

class RunHooks {
 public:
  explicit RunHooks(py::object progress) : progress_(std::move(progress)) {}

  /// For CapsuleRunOptions::should_stop (called without the GIL).
  std::function<bool()> should_stop() {
    return [this]() {
      py::gil_scoped_acquire gil;
      if (!pending_ && PyErr_CheckSignals() != 0) pending_.emplace();
      return pending_.has_value();
    };
  }
  /// For CapsuleRunOptions::on_progress; empty without a progress callable. The dict holds time,
  /// t_end, dt, steps, elapsed_seconds, eta_seconds, final, and the recorder's measures by name.
  std::function<void(const CapsuleProgress&)> on_progress() {
    if (progress_.is_none()) return nullptr;
    return [this](const CapsuleProgress& p) {
      py::gil_scoped_acquire gil;
      if (pending_) return;
      try {
        py::dict d(py::arg("time") = p.time, py::arg("t_end") = p.t_end, py::arg("dt") = p.dt,
                   py::arg("steps") = p.steps, py::arg("elapsed_seconds") = p.elapsed_seconds,
                   py::arg("eta_seconds") = p.eta_seconds, py::arg("final") = p.final);
        for (const auto& [name, value] : p.measures) d[py::str(name)] = value;
        progress_(d);
      } catch (py::error_already_set& e) {
        pending_.emplace(std::move(e));
      }
    };
  }
  /// Raises what stopped the run, if anything did.
  void rethrow() {
    if (pending_) throw std::move(*pending_);
  }

 private:
  py::object progress_;
  std::optional<py::error_already_set> pending_;
};

}  // namespace bendlab::python
