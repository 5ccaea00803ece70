// Shared numpy conversions of bind_lie.cpp, bind_graph.cpp, bind_inertial.cpp
// and bind_filters.cpp: float64 arrays checked for shape (with messages that
// name the function and the argument), stacks of fixed-size matrices and
// vectors with any leading shape, and row-major Eigen maps onto them.
//
// Inputs go through py::array_t<double, c_style | forcecast>: a C-contiguous
// float64 array is used in place, anything else numpy can convert (ints,
// lists, Fortran order, strided views) is converted once. numpy is imported
// on the first call that needs it, never when the module is imported.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include <posefuse/core/error.hpp>
#include <posefuse/lie/se3.hpp>

namespace posefuse::python::math {

namespace py = pybind11;

using Arr = py::array_t<double, py::array::c_style | py::array::forcecast>;
using Shape = std::vector<py::ssize_t>;

/// Raises ImportError with a clear sentence when numpy is missing.
inline void require_numpy(const char* fn) {
  static bool ok = false;  // set once numpy imported (module-level state of the extension, not of the library)
  if (ok) return;
  try {
    py::module_::import("numpy");
  } catch (py::error_already_set&) {
    throw py::import_error(std::string(fn) +
                           " needs numpy (Debian: apt install python3-numpy, and run /usr/bin/python3)");
  }
  ok = true;
}

/// "(2, 3, 3)"
inline std::string shape_text(const py::array& a) {
  std::string s = "(";
  for (py::ssize_t k = 0; k < a.ndim(); ++k) {
    if (k) s += ", ";
    s += std::to_string(a.shape(k));
  }
  if (a.ndim() == 1) s += ",";
  return s + ")";
}

/// "(..., 3, 3)" or "(N, 3)" text of an expected shape.
inline std::string tail_text(const Shape& tail, const char* lead) {
  std::string s = "(";
  s += lead;
  for (py::ssize_t d : tail) s += ", " + std::to_string(d);
  if (tail.empty() && std::string(lead) != "...") s += ",";
  return s + ")";
}

/// "(3, 3)" or "(3,)".
inline std::string exact_text(const Shape& shape) {
  std::string s = "(";
  for (std::size_t k = 0; k < shape.size(); ++k) s += (k ? ", " : "") + std::to_string(shape[k]);
  if (shape.size() == 1) s += ",";
  return s + ")";
}

/// Any object as a C-contiguous float64 array, or TypeError naming `what`.
inline Arr to_array(const py::handle& obj, const std::string& what) {
  if (obj.is_none()) throw py::type_error(what + ": expected a float64 array, got None");
  Arr a = Arr::ensure(obj);
  if (!a) {
    PyErr_Clear();
    throw py::type_error(what + ": cannot be converted to a float64 array (got " +
                         std::string(py::str(py::type::handle_of(obj).attr("__name__"))) + ")");
  }
  return a;
}

/// A stack of items of shape `tail` under any leading shape.
struct Stack {
  Arr a;
  Shape lead;            ///< leading shape
  py::ssize_t n = 1;     ///< number of items (product of lead)
  py::ssize_t size = 1;  ///< doubles per item
  [[nodiscard]] const double* item(py::ssize_t i) const { return a.data() + (n == 1 ? 0 : i) * size; }
};

/// `obj` as a stack of `tail`-shaped items (ValueError naming `what` otherwise).
inline Stack stack_of(const py::handle& obj, const Shape& tail, const std::string& what) {
  Stack s;
  s.a = to_array(obj, what);
  const py::ssize_t nd = s.a.ndim(), nt = py::ssize_t(tail.size());
  bool ok = nd >= nt;
  for (py::ssize_t k = 0; ok && k < nt; ++k) ok = s.a.shape(nd - nt + k) == tail[std::size_t(k)];
  if (!ok)
    throw py::value_error(what + ": expected an array of shape " + tail_text(tail, "...") + ", got " +
                          shape_text(s.a));
  for (py::ssize_t k = 0; k < nd - nt; ++k) {
    s.lead.push_back(s.a.shape(k));
    s.n *= s.a.shape(k);
  }
  for (py::ssize_t d : tail) s.size *= d;
  return s;
}

/// `obj` as exactly `n` items of shape `tail`: shape (n, *tail).
inline Stack rows_of(const py::handle& obj, py::ssize_t n, const Shape& tail, const std::string& what) {
  Stack s = stack_of(obj, tail, what);
  if (s.lead.size() != 1 || s.lead[0] != n) {
    Shape want{n};
    want.insert(want.end(), tail.begin(), tail.end());
    throw py::value_error(what + ": expected an array of shape " + exact_text(want) + ", got " + shape_text(s.a));
  }
  return s;
}

/// `obj` as one item of shape `tail` (no leading dimensions).
inline Stack single(const py::handle& obj, const Shape& tail, const std::string& what) {
  Stack s;
  s.a = to_array(obj, what);
  bool ok = s.a.ndim() == py::ssize_t(tail.size());
  for (std::size_t k = 0; ok && k < tail.size(); ++k) ok = s.a.shape(py::ssize_t(k)) == tail[k];
  if (!ok)
    throw py::value_error(what + ": expected an array of shape " + exact_text(tail) + ", got " + shape_text(s.a));
  for (py::ssize_t d : tail) s.size *= d;
  return s;
}

/// The leading shape of a two-argument operation: equal leading shapes, or
/// one side a single item (broadcast).
inline Shape broadcast(const Stack& a, const Stack& b, const std::string& what) {
  if (a.lead == b.lead) return a.lead;
  if (a.n == 1) return b.lead;
  if (b.n == 1) return a.lead;
  throw py::value_error(what + ": leading shapes " + shape_text(a.a) + " and " + shape_text(b.a) +
                        " do not match (equal, or one of them a single element)");
}

inline py::ssize_t count(const Shape& lead) {
  py::ssize_t n = 1;
  for (py::ssize_t d : lead) n *= d;
  return n;
}

/// A new float64 array of shape lead + tail.
inline py::array_t<double> make(const Shape& lead, const Shape& tail) {
  Shape s = lead;
  s.insert(s.end(), tail.begin(), tail.end());
  return py::array_t<double>(s);
}

/// Row-major map type (Eigen refuses RowMajor for column vectors).
template <int R, int C>
using RowMajorMatrix = Eigen::Matrix<double, R, C, (C == 1 && R != 1) ? Eigen::ColMajor : Eigen::RowMajor>;

template <int R, int C>
inline Eigen::Matrix<double, R, C> read(const double* p) {
  return Eigen::Map<const RowMajorMatrix<R, C>>(p);
}
template <int R, int C, class M>
inline void write(double* p, const M& m) {
  Eigen::Map<RowMajorMatrix<R, C>> dst(p);
  dst = m;
}

/// One fixed-size matrix / vector from `obj` (shape (R, C), or (R,) for C = 1).
template <int R, int C>
inline Eigen::Matrix<double, R, C> matrix_arg(const py::handle& obj, const std::string& what) {
  const Stack s = single(obj, C == 1 ? Shape{R} : Shape{R, C}, what);
  return read<R, C>(s.a.data());
}

/// A fixed-size matrix as a new numpy array ((R,) for C = 1).
template <int R, int C>
inline py::array_t<double> to_numpy(const Eigen::Matrix<double, R, C>& m) {
  py::array_t<double> out = C == 1 ? make({}, {R}) : make({}, {R, C});
  write<R, C>(out.mutable_data(), m);
  return out;
}

/// An integer array (any integer dtype) as int64 of shape (n,) (n = -1: any);
/// TypeError for floats, None or anything else.
inline py::array_t<std::int64_t> int_array(const py::handle& obj, py::ssize_t n, const std::string& what) {
  if (obj.is_none()) throw py::type_error(what + ": expected an integer array, got None");
  py::array a = py::array::ensure(obj);
  if (!a) {
    PyErr_Clear();
    throw py::type_error(what + ": cannot be converted to an integer array");
  }
  const char kind = a.dtype().kind();
  if (kind != 'i' && kind != 'u') throw py::type_error(what + ": expected integers, got dtype " + std::string(py::str(a.dtype())));
  auto out = py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>::ensure(a);
  if (out.ndim() != 1 || (n >= 0 && out.shape(0) != n))
    throw py::value_error(what + ": expected an array of shape (" + (n >= 0 ? std::to_string(n) : std::string("N")) +
                          ",), got " + shape_text(a));
  return out;
}

/// The SE(3) element of a 4x4 homogeneous matrix, checked as the C++ isometry
/// constructor checks it (rotation within 1e-5, finite translation), plus the
/// bottom row [0 0 0 1] within 1e-5.
inline SE3d se3_from_matrix(const Eigen::Matrix4d& T) {
  if (!((T.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).cwiseAbs().maxCoeff() <= SO3d::kDefaultOrthonormalityTolerance))
    throw invalid_argument("SE3: bottom row of the matrix is not [0 0 0 1]");
  Eigen::Isometry3d iso = Eigen::Isometry3d::Identity();
  iso.linear() = T.topLeftCorner<3, 3>();
  iso.translation() = T.topRightCorner<3, 1>();
  return SE3d(iso);
}

/// A finite real number or ValueError naming `what`.
inline double finite(double v, const std::string& what) {
  if (!std::isfinite(v)) throw py::value_error(what + " must be finite, got " + std::to_string(v));
  return v;
}

}  // namespace posefuse::python::math
