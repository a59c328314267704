#include "arrays.hpp"

#include <fmt/format.h>

#include <cmath>

namespace bendlab::python {

namespace {

py::array as_array(const py::handle& obj, const char* name, const char* expected) {
  if (!py::isinstance<py::array>(obj))
    throw py::value_error(fmt::format("{}: expected a numpy array ({}), got {}", name, expected,
                                      std::string(py::str(py::type::of(obj).attr("__name__")))));
  return py::reinterpret_borrow<py::array>(obj);
}

void require_rows_of_three(const py::array& a, const char* name, const char* expected) {
  if (a.ndim() != 2 || a.shape(1) != 3) {
    std::string shape = "(";
    for (py::ssize_t d = 0; d < a.ndim(); ++d) shape += (d ? ", " : "") + std::to_string(a.shape(d));
    throw py::value_error(fmt::format("{}: expected shape (N, 3) ({}), got {}{})", name, expected, shape,
                                      a.ndim() == 1 ? "," : ""));
  }
  if (!(a.flags() & py::array::c_style))
    throw py::value_error(fmt::format("{}: the array must be C-contiguous (use numpy.ascontiguousarray)", name));
}

template <class Matrix>
py::array array_of(const Matrix& m, const py::handle& owner) {
  using T = typename Matrix::Scalar;
  std::vector<py::ssize_t> shape, strides;
  if constexpr (Matrix::ColsAtCompileTime == 1) {
    shape = {static_cast<py::ssize_t>(m.rows())};
    strides = {static_cast<py::ssize_t>(sizeof(T))};
  } else {
    shape = {static_cast<py::ssize_t>(m.rows()), 3};
    strides = {static_cast<py::ssize_t>(3 * sizeof(T)), static_cast<py::ssize_t>(sizeof(T))};
  }
  return py::array(py::dtype::of<T>(), shape, strides, m.data(), owner);
}

template <class Matrix>
py::array view_of(const Matrix& m, const py::handle& owner) {
  py::array a = array_of(m, owner);
  a.attr("setflags")(py::arg("write") = false);
  return a;
}

template <class Matrix>
py::array take_of(Matrix&& m) {
  auto* owned = new Matrix(std::move(m));
  py::capsule base(owned, [](void* p) { delete static_cast<Matrix*>(p); });
  return array_of(*owned, base);
}

}  // namespace

Points points_from(const py::handle& obj, const char* name) {
  const char* expected = "float64, shape (N, 3)";
  const py::array a = as_array(obj, name, expected);
  if (!a.dtype().is(py::dtype::of<double>()))
    throw py::value_error(fmt::format("{}: expected float64 values, got dtype {}", name,
                                      std::string(py::str(a.dtype()))));
  require_rows_of_three(a, name, expected);
  const auto n = static_cast<Eigen::Index>(a.shape(0));
  Points p = Eigen::Map<const Points>(static_cast<const double*>(a.data()), n, 3);
  for (Eigen::Index i = 0; i < n; ++i)
    if (!p.row(i).allFinite())
      throw py::value_error(fmt::format("{}: row {} is not finite ({}, {}, {})", name, i, p(i, 0), p(i, 1), p(i, 2)));
  return p;
}

Faces faces_from(const py::handle& obj, const char* name) {
  const char* expected = "integers, shape (F, 3)";
  const py::array a = as_array(obj, name, expected);
  const char kind = a.dtype().kind();
  if (kind != 'i' && kind != 'u')
    throw py::value_error(fmt::format("{}: expected integer vertex indices, got dtype {}", name,
                                      std::string(py::str(a.dtype()))));
  require_rows_of_three(a, name, expected);
  // Any integer width: let numpy convert to int64 (exact), then check the range of int.
  const auto wide = py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>::ensure(a);
  Faces f(a.shape(0), 3);
  const std::int64_t* d = wide.data();
  for (py::ssize_t i = 0; i < 3 * a.shape(0); ++i) {
    if (d[i] < 0 || d[i] > std::numeric_limits<int>::max())
      throw py::value_error(fmt::format("{}: face {} has the vertex index {}, outside [0, {}]", name, i / 3, d[i],
                                        std::numeric_limits<int>::max()));
    f.data()[i] = static_cast<int>(d[i]);
  }
  return f;
}

py::array view(const Points& p, const py::handle& owner) { return view_of(p, owner); }
py::array view(const Faces& f, const py::handle& owner) { return view_of(f, owner); }
py::array view(const Scalars& s, const py::handle& owner) { return view_of(s, owner); }
py::array take(Points&& p) { return take_of(std::move(p)); }
py::array take(Scalars&& s) { return take_of(std::move(s)); }

}  // namespace bendlab::python
