// posefuse._posefuse: the compiled half of the Python package `posefuse`
// (python/posefuse/__init__.py re-exports it). Each area is bound in its own
// translation unit; python/CMakeLists.txt defines POSEFUSE_PY_HAS_<AREA> for
// every python/src/bind_<area>.cpp it compiles.
#include "bindings.hpp"

PYBIND11_MODULE(_posefuse, m) {
  m.doc() = "posefuse: trajectory evaluation, Lie groups, pose graphs, IMU pre-integration and filters";
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
