// Conversions between numpy arrays and posefuse's C++ types, shared by the
// bind_*.cpp files of posefuse._posefuse.
//
// Rules: numpy is imported when a function first needs it, never at module
// import (`require_numpy` raises ImportError with a sentence saying so);
// inputs are accepted from anything numpy can convert to float64 (lists,
// other dtypes, non-contiguous arrays: converted, a copy only then), None
// and unconvertible objects raise TypeError, wrong shapes ValueError;
// outputs that live inside a C++ object are read-only views on its memory
// (the array keeps the object alive), the others are fresh arrays.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstddef>
#include <initializer_list>
#include <string>
#include <vector>

namespace posefuse::python {

namespace py = pybind11;

/// A C-contiguous float64 array (numpy's own type).
using DoubleArray = py::array_t<double, py::array::c_style | py::array::forcecast>;

/// Imports numpy or raises ImportError naming `what`.
inline void require_numpy(const char* what) {
  try {
    (void)py::module_::import("numpy");
  } catch (py::error_already_set&) {
    throw py::import_error(std::string(what) +
                           " needs numpy, which this Python cannot import (Debian: apt install "
                           "python3-numpy; `import posefuse` itself works without it)");
  }
}

/// `obj` as a C-contiguous float64 array, converting (copying) only when it
/// is not one already.
/// @throws TypeError for None or what numpy cannot convert to float64
inline DoubleArray to_double_array(const py::handle& obj, const char* name) {
  require_numpy(name);
  if (obj.is_none()) throw py::type_error(std::string(name) + " must be an array of numbers, not None");
  DoubleArray a = DoubleArray::ensure(obj);
  if (!a) {
    PyErr_Clear();
    throw py::type_error(std::string(name) + " must be an array of numbers convertible to float64, got " +
                         std::string(py::str(py::type::of(obj).attr("__name__"))));
  }
  return a;
}

/// "(5, 3)" for an array's shape.
inline std::string shape_text(const py::array& a) {
  std::string s = "(";
  for (py::ssize_t d = 0; d < a.ndim(); ++d) {
    if (d > 0) s += ", ";
    s += std::to_string(a.shape(d));
  }
  return s + (a.ndim() == 1 ? ",)" : ")");
}

/// Checks `a`'s shape against `expected` (-1: any length, the N), naming
/// the argument and the expected shape `spelled` (e.g. "(N, 3)").
/// @throws ValueError on a mismatch
inline void check_shape(const py::array& a, std::initializer_list<py::ssize_t> expected, const char* name,
                        const char* spelled) {
  bool ok = a.ndim() == static_cast<py::ssize_t>(expected.size());
  py::ssize_t d = 0;
  for (const py::ssize_t e : expected) {
    if (!ok) break;
    ok = e < 0 || a.shape(d) == e;
    ++d;
  }
  if (!ok) throw py::value_error(std::string(name) + " must have shape " + spelled + ", got " + shape_text(a));
}

/// A read-only float64 view on `data` (no copy) that keeps `owner` alive.
inline py::array readonly_view(const double* data, std::vector<py::ssize_t> shape,
                               std::vector<py::ssize_t> strides_bytes, const py::handle& owner) {
  py::array a(py::dtype::of<double>(), std::move(shape), std::move(strides_bytes), data, owner);
  a.attr("setflags")(py::arg("write") = false);
  return a;
}

/// A fresh float64 array of the given shape (C order).
inline DoubleArray new_array(std::vector<py::ssize_t> shape) { return DoubleArray(std::move(shape)); }

/// Stride between consecutive poses of a std::vector<Eigen::Isometry3d>
/// (each a column-major 4x4 matrix).
inline constexpr py::ssize_t kPoseStride = static_cast<py::ssize_t>(sizeof(Eigen::Isometry3d));
static_assert(sizeof(Eigen::Isometry3d) == 16 * sizeof(double), "Isometry3d is a plain 4x4 matrix");

/// (N, 4, 4) read-only view of poses (rows, columns as written).
inline py::array poses_view(const std::vector<Eigen::Isometry3d>& poses, const py::handle& owner) {
  const auto n = static_cast<py::ssize_t>(poses.size());
  constexpr auto d = static_cast<py::ssize_t>(sizeof(double));
  return readonly_view(poses.empty() ? nullptr : poses.front().matrix().data(), {n, 4, 4},
                       {kPoseStride, d, 4 * d}, owner);
}

/// (N, 3) read-only view of the translations of poses.
inline py::array positions_view(const std::vector<Eigen::Isometry3d>& poses, const py::handle& owner) {
  const auto n = static_cast<py::ssize_t>(poses.size());
  constexpr auto d = static_cast<py::ssize_t>(sizeof(double));
  return readonly_view(poses.empty() ? nullptr : poses.front().matrix().data() + 12, {n, 3}, {kPoseStride, d},
                       owner);
}

/// (N,) read-only view of a vector of doubles.
inline py::array vector_view(const std::vector<double>& v, const py::handle& owner) {
  return readonly_view(v.data(), {static_cast<py::ssize_t>(v.size())}, {static_cast<py::ssize_t>(sizeof(double))},
                       owner);
}

/// A 3x3 or other fixed matrix as a fresh (rows, cols) array.
template <class Derived>
DoubleArray matrix_array(const Eigen::MatrixBase<Derived>& m) {
  DoubleArray a = new_array({static_cast<py::ssize_t>(m.rows()), static_cast<py::ssize_t>(m.cols())});
  auto r = a.mutable_unchecked<2>();
  for (Eigen::Index i = 0; i < m.rows(); ++i)
    for (Eigen::Index j = 0; j < m.cols(); ++j) r(i, j) = m(i, j);
  return a;
}

/// A vector as a fresh (n,) array.
template <class Derived>
DoubleArray vector_array(const Eigen::MatrixBase<Derived>& v) {
  DoubleArray a = new_array({static_cast<py::ssize_t>(v.size())});
  auto r = a.mutable_unchecked<1>();
  for (Eigen::Index i = 0; i < v.size(); ++i) r(i) = v(i);
  return a;
}

}  // namespace posefuse::python
