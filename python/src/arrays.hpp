#pragma once
// numpy <-> bendlab arrays.
//
// In: arrays are checked, never silently converted: vertex arrays must be float64, C-contiguous,
// shape (N, 3) and finite; face arrays integer (any width), C-contiguous, shape (F, 3). Anything
// else raises ValueError naming the argument and what was expected.
// Out: results are returned without copies: the numpy array views memory owned by a C++ object
// that the array keeps alive (its `base`), and is read-only when that memory belongs to a
// library object the caller must not change behind its back.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <string>

#include "bendlab/core/types.hpp"

namespace bendlab::python {

namespace py = pybind11;

/// (N, 3) float64 C-contiguous finite array -> Points (one copy into the library's own type).
Points points_from(const py::handle& array, const char* name);
/// (F, 3) integer C-contiguous array -> Faces.
Faces faces_from(const py::handle& array, const char* name);

/// A read-only view of data owned by `owner` (which the array keeps alive).
py::array view(const Points& p, const py::handle& owner);
py::array view(const Faces& f, const py::handle& owner);
py::array view(const Scalars& s, const py::handle& owner);

/// Moves a result into a new numpy array that owns it (writeable, no copy of the data).
py::array take(Points&& p);
py::array take(Scalars&& s);

}  // namespace bendlab::python
