#pragma once
// One function per concept adds its classes and functions to the module.
#include <pybind11/pybind11.h>

namespace bendlab::python {

void bind_mesh(pybind11::module_& m);
void bind_bending(pybind11::module_& m);
void bind_surfaces(pybind11::module_& m);
void bind_capsule(pybind11::module_& m);
void bind_flow(pybind11::module_& m);

}  // namespace bendlab::python
