// The Python module bendlab._bendlab (imported by the package bendlab).
//
// Every bendlab::Error (bad input, a mesh the library refuses, an unknown method or option)
// raises ValueError with the library's one-line message.
#include <pybind11/pybind11.h>

#include "bendlab/core/types.hpp"
#include "bindings.hpp"

namespace py = pybind11;

PYBIND11_MODULE(_bendlab, m) {
  m.doc() = "bendlab: membrane bending forces on triangulated surfaces, checked against exact analytic "
            "results, and elastic capsules in flow (Guckenberger et al. 2016, 'On the bending algorithms "
            "for soft objects in flows').";
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const bendlab::Error& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    }
  });
  bendlab::python::bind_mesh(m);
  bendlab::python::bind_surfaces(m);
  bendlab::python::bind_bending(m);
  bendlab::python::bind_capsule(m);
  bendlab::python::bind_flow(m);
}
