// The Python module posefuse._posefuse is assembled from one translation unit
// per area; each defines one of these functions and module.cpp calls them.
#pragma once

#include <pybind11/pybind11.h>

namespace posefuse::python {

void bind_trajectory(pybind11::module_& m);  // bind_trajectory.cpp: Trajectory, read/write, association
void bind_eval(pybind11::module_& m);        // bind_eval.cpp: ape, rpe, align, results
void bind_lie(pybind11::module_& m);         // bind_lie.cpp: SO2, SE2, SO3, SE3
void bind_graph(pybind11::module_& m);       // bind_graph.cpp: pose graphs, g2o
void bind_inertial(pybind11::module_& m);    // bind_inertial.cpp: pre-integration, IMU factor, alignment
void bind_filters(pybind11::module_& m);     // bind_filters.cpp: EKF on the built-in models, RTS

}  // namespace posefuse::python
