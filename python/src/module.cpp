// posefuse._posefuse: the compiled half of the Python package `posefuse`
// (python/posefuse/__init__.py re-exports it). Each area is bound in its own
// translation unit; python/CMakeLists.txt defines POSEFUSE_PY_HAS_<AREA> for
// every python/src/bind_<area>.cpp it compiles.
#include <exception>

#include <apps/cli.hpp>
#include <posefuse/core/error.hpp>
#include <posefuse/io/read_options.hpp>

#include "bindings.hpp"

namespace {

namespace py = pybind11;

/// A new exception class posefuse.<name> with the given bases, added to `m`.
PyObject* add_exception(py::module_& m, const char* name, py::tuple bases, const char* doc) {
  const std::string qualified = std::string("posefuse.") + name;
  PyObject* cls = PyErr_NewExceptionWithDoc(qualified.c_str(), doc, bases.ptr(), nullptr);
  if (cls == nullptr) throw py::error_already_set();
  m.add_object(name, py::handle(cls));  // the module keeps a reference; `cls` is never released
  return cls;
}

/// posefuse's C++ exceptions as Python exceptions with the same text:
///   posefuse::repeated_stamp_error -> RepeatedStampError (FileError)
///   posefuse::io_error             -> FileError (Error, OSError): "file:line: reason"
///   posefuse::invalid_argument     -> InvalidArgument (Error, ValueError)
///   data errors of an evaluation   -> DataError (Error, ValueError)
///   option errors of an evaluation -> InvalidArgument
void register_errors(py::module_& m) {
  PyObject* error = add_exception(m, "Error", py::make_tuple(py::handle(PyExc_Exception)),
                                  "Base class of posefuse's exceptions.");
  static PyObject* file_error = add_exception(
      m, "FileError", py::make_tuple(py::handle(error), py::handle(PyExc_OSError)),
      "A trajectory or data file that cannot be read or is malformed; the text is \"file:line: reason\".");
  static PyObject* repeated_stamp_error = add_exception(
      m, "RepeatedStampError", py::make_tuple(py::handle(file_error)),
      "A repeated timestamp refused under duplicates='error' (read with 'first', 'last' or 'keep' instead).");
  static PyObject* invalid_argument = add_exception(
      m, "InvalidArgument", py::make_tuple(py::handle(error), py::handle(PyExc_ValueError)),
      "A value the library cannot work with (a ValueError).");
  static PyObject* data_error = add_exception(
      m, "DataError", py::make_tuple(py::handle(error), py::handle(PyExc_ValueError)),
      "Trajectories that cannot be evaluated as asked (no matching stamps, a degenerate alignment, ...).");
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const posefuse::repeated_stamp_error& e) {
      PyErr_SetString(repeated_stamp_error, e.what());
    } catch (const posefuse::io_error& e) {
      PyErr_SetString(file_error, e.what());
    } catch (const posefuse::invalid_argument& e) {
      PyErr_SetString(invalid_argument, e.what());
    } catch (const posefuse::apps::data_error& e) {
      PyErr_SetString(data_error, e.what());
    } catch (const posefuse::apps::usage_error& e) {
      PyErr_SetString(invalid_argument, e.what());
    }
  });
}

}  // namespace

PYBIND11_MODULE(_posefuse, m) {
  m.doc() = "posefuse: trajectory evaluation, Lie groups, pose graphs, IMU pre-integration and filters";
  m.attr("__version__") = POSEFUSE_VERSION;  // CMake's project(VERSION), from python/CMakeLists.txt
  register_errors(m);
#ifdef POSEFUSE_PY_HAS_TRAJECTORY
  posefuse::python::bind_trajectory(m);
#endif
#ifdef POSEFUSE_PY_HAS_EVAL
  posefuse::python::bind_eval(m);
#endif
#ifdef POSEFUSE_PY_HAS_LIE
  posefuse::python::bind_lie(m);
#endif
#ifdef POSEFUSE_PY_HAS_GRAPH
  posefuse::python::bind_graph(m);
#endif
#ifdef POSEFUSE_PY_HAS_INERTIAL
  posefuse::python::bind_inertial(m);
#endif
#ifdef POSEFUSE_PY_HAS_FILTERS
  posefuse::python::bind_filters(m);
#endif
}
