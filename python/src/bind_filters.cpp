// posefuse.ekf_seed000 / ekf_constant_velocity / ekf_unicycle /
// ekf_se2_odometry / EkfRun / rts_smooth: the EKF (filters/ekf.hpp) on the
// library's built-in models, stepped over numpy arrays of controls and
// measurements, and RTS smoothing (filters/rts_smoother.hpp) of the run.
//
// Step k (k = 0 .. N-1): predict from state k-1 (the prior x0 for k = 0)
// with control k over dt k, then update with measurement k when mask[k].
#include <pybind11/stl.h>

#include <Eigen/Core>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <posefuse/core/gaussian.hpp>
#include <posefuse/filters/ekf.hpp>
#include <posefuse/filters/rts_smoother.hpp>
#include <posefuse/lie/se2.hpp>
#include <posefuse/models/constant_velocity.hpp>
#include <posefuse/models/planar_displacement.hpp>
#include <posefuse/models/planar_pose.hpp>
#include <posefuse/models/planar_pose_fix.hpp>
#include <posefuse/models/position.hpp>
#include <posefuse/models/se2_odometry.hpp>
#include <posefuse/models/unicycle.hpp>

#include "bindings.hpp"
#include "math_helpers.hpp"

namespace posefuse::python {
namespace {

namespace py = pybind11;
using namespace math;

/// A recorded EKF run (arrays of the N steps).
struct EkfRun {
  std::string model;
  py::array_t<double> states, covariances, predicted_states, predicted_covariances, jacobians, nis, innovations;
  std::vector<std::string> status;
};

/// A copy of a recorded array: the run stays as recorded whatever the caller does with it.
py::array_t<double> copy(const py::array_t<double>& a) { return py::array_t<double>(a.attr("copy")()); }

template <int D>
Eigen::Matrix<double, D, 1> vec(const Eigen::Matrix<double, D, 1>& x) {
  return x;
}
inline Eigen::Vector3d vec(const PlanarPose<double>& x) { return x.vector(); }

template <class S>
S state_of(const Eigen::Matrix<double, DimOf<S>, 1>& v) {
  if constexpr (std::is_same_v<S, PlanarPose<double>>) {
    return PlanarPose<double>{v(0), v(1), v(2)};
  } else {
    return v;
  }
}

/// The mask (N,) of steps with a measurement (all when None).
std::vector<char> mask_of(const py::object& mask, py::ssize_t n, const std::string& fn) {
  std::vector<char> m(std::size_t(n), 1);
  if (mask.is_none()) return m;
  auto a = py::array_t<bool, py::array::c_style | py::array::forcecast>::ensure(mask);
  if (!a || a.ndim() != 1 || a.shape(0) != n) {
    PyErr_Clear();
    throw py::value_error(fn + ": mask: expected a bool array of shape (" + std::to_string(n) + ",)");
  }
  for (py::ssize_t k = 0; k < n; ++k) m[std::size_t(k)] = a.at(k) ? 1 : 0;
  return m;
}

/// dt as (N,) from a scalar or an array; finite and >= 0.
std::vector<double> dt_of(const py::object& dt, py::ssize_t n, const std::string& fn) {
  std::vector<double> out(static_cast<std::size_t>(n));
  const Arr a = to_array(dt, fn + ": dt");
  if (a.ndim() == 0) {
    std::fill(out.begin(), out.end(), a.data()[0]);
  } else if (a.ndim() == 1 && a.shape(0) == n) {
    std::copy(a.data(), a.data() + n, out.begin());
  } else {
    throw py::value_error(fn + ": dt: expected a number or an array of shape (" + std::to_string(n) + ",), got " +
                          shape_text(a));
  }
  for (std::size_t k = 0; k < out.size(); ++k)
    if (!(std::isfinite(out[k]) && out[k] >= 0))
      throw py::value_error(fn + ": dt[" + std::to_string(k) + "] must be finite and >= 0, got " +
                            std::to_string(out[k]));
  return out;
}

/// Runs `ekf` over the steps; control(k) and measurement(k) give the inputs.
template <int D, int M, class Filter, class Control, class Measurement>
EkfRun run(Filter& ekf, const std::string& fn, const std::string& model, const py::object& x0_, const py::object& P0_,
           py::ssize_t n, const std::vector<double>& dt, Control control, Measurement measurement,
           const std::vector<char>& mask, double gate) {
  using S = typename Filter::StateType;
  const Eigen::Matrix<double, D, 1> x0 = matrix_arg<D, 1>(x0_, fn + ": x0");
  const Eigen::Matrix<double, D, D> P0 = matrix_arg<D, D>(P0_, fn + ": P0");
  ekf.reset(state_of<S>(x0), P0);
  if (!std::isinf(gate) || gate < 0) ekf.template set_gate<0>(gate);
  EkfRun r;
  r.model = model;
  r.states = make({n}, {D});
  r.covariances = make({n}, {D, D});
  r.predicted_states = make({n}, {D});
  r.predicted_covariances = make({n}, {D, D});
  r.jacobians = make({n}, {D, D});
  r.nis = make({n}, {});
  r.innovations = make({n}, {M});
  r.status.reserve(std::size_t(n));
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (py::ssize_t k = 0; k < n; ++k) {
    const FilterStatus ps = ekf.predict(control(k), dt[std::size_t(k)]);
    if (ps != FilterStatus::kApplied)
      throw invalid_argument(fn + ": step " + std::to_string(k) + ": prediction: " + to_string(ps));
    write<D, 1>(r.predicted_states.mutable_data() + k * D, vec(ekf.state()));
    write<D, D>(r.predicted_covariances.mutable_data() + k * D * D, ekf.covariance());
    write<D, D>(r.jacobians.mutable_data() + k * D * D, ekf.last_jacobian());
    double* nis = r.nis.mutable_data() + k;
    double* inn = r.innovations.mutable_data() + k * M;
    *nis = nan;
    std::fill(inn, inn + M, nan);
    if (mask[std::size_t(k)]) {
      const auto u = ekf.template update<0>(measurement(k));
      if (u.status == FilterStatus::kNonFinite || u.status == FilterStatus::kInvalidInput)
        throw invalid_argument(fn + ": step " + std::to_string(k) + ": update: " + to_string(u.status));
      *nis = u.nis;
      write<M, 1>(inn, u.innovation);
      r.status.emplace_back(to_string(u.status));
    } else {
      r.status.emplace_back("no measurement");
    }
    write<D, 1>(r.states.mutable_data() + k * D, vec(ekf.state()));
    write<D, D>(r.covariances.mutable_data() + k * D * D, ekf.covariance());
  }
  return r;
}

EkfRun ekf_seed000(const py::object& x0, const py::object& P0, const py::object& u_, const py::object& z_,
                   const py::object& R, const py::object& Q, const py::object& mask_, double gate) {
  const std::string fn = "ekf_seed000";
  require_numpy(fn.c_str());
  const Stack u = stack_of(u_, {2}, fn + ": displacements");
  if (u.lead.size() != 1) throw py::value_error(fn + ": displacements: expected an array of shape (N, 2), got " + shape_text(u.a));
  const py::ssize_t n = u.lead[0];
  const Stack z = rows_of(z_, n, {2}, fn + ": fixes");
  Ekf<PlanarDisplacement<double>, PositionFix<2, 2, double>> ekf(
      PlanarDisplacement<double>(matrix_arg<2, 2>(R, fn + ": R")),
      PositionFix<2, 2, double>(matrix_arg<2, 2>(Q, fn + ": Q")));
  return run<2, 2>(
      ekf, fn, "seed000", x0, P0, n, std::vector<double>(std::size_t(n), 0.0),
      [&](py::ssize_t k) { return read<2, 1>(u.item(k)); }, [&](py::ssize_t k) { return read<2, 1>(z.item(k)); },
      mask_of(mask_, n, fn), gate);
}

EkfRun ekf_cv(const py::object& x0, const py::object& P0, const py::object& dt_, const py::object& z_, double q,
              const py::object& R, const py::object& mask_, double gate) {
  const std::string fn = "ekf_constant_velocity";
  require_numpy(fn.c_str());
  const Stack z = stack_of(z_, {2}, fn + ": fixes");
  if (z.lead.size() != 1) throw py::value_error(fn + ": fixes: expected an array of shape (N, 2), got " + shape_text(z.a));
  const py::ssize_t n = z.lead[0];
  Ekf<ConstantVelocity2<double>, PositionFix<4, 2, double>> ekf(
      ConstantVelocity2<double>(q), PositionFix<4, 2, double>(matrix_arg<2, 2>(R, fn + ": R")));
  return run<4, 2>(
      ekf, fn, "constant_velocity", x0, P0, n, dt_of(dt_, n, fn), [](py::ssize_t) { return NoControl{}; },
      [&](py::ssize_t k) { return read<2, 1>(z.item(k)); }, mask_of(mask_, n, fn), gate);
}

EkfRun ekf_unicycle(const py::object& x0, const py::object& P0, const py::object& u_, const py::object& dt_,
                    const py::object& z_, const py::object& control_cov, const py::object& R,
                    const std::string& integration, const py::object& mask_, double gate) {
  const std::string fn = "ekf_unicycle";
  require_numpy(fn.c_str());
  const Stack u = stack_of(u_, {2}, fn + ": controls");
  if (u.lead.size() != 1) throw py::value_error(fn + ": controls: expected an array of shape (N, 2), got " + shape_text(u.a));
  const py::ssize_t n = u.lead[0];
  const Stack z = rows_of(z_, n, {3}, fn + ": fixes");
  Unicycle<double> motion;
  if (integration == "exact_arc") motion.method = Integration::kExactArc;
  else if (integration == "euler") motion.method = Integration::kEuler;
  else throw py::value_error(fn + ": integration must be 'exact_arc' or 'euler', got '" + integration + "'");
  motion.control_cov = matrix_arg<2, 2>(control_cov, fn + ": control_cov");
  require_covariance(motion.control_cov, "ekf_unicycle: control_cov");
  Ekf<Unicycle<double>, PlanarPoseFix<double>> ekf(motion, PlanarPoseFix<double>(matrix_arg<3, 3>(R, fn + ": R")));
  return run<3, 3>(
      ekf, fn, "unicycle", x0, P0, n, dt_of(dt_, n, fn), [&](py::ssize_t k) { return read<2, 1>(u.item(k)); },
      [&](py::ssize_t k) {
        const double* p = z.item(k);
        return PlanarPose<double>{p[0], p[1], p[2]};
      },
      mask_of(mask_, n, fn), gate);
}

EkfRun ekf_se2_odometry(const py::object& x0, const py::object& P0, const py::object& u_, const py::object& z_,
                        const py::object& R, double kxy, double kts, double ktt, const py::object& mask_, double gate) {
  const std::string fn = "ekf_se2_odometry";
  require_numpy(fn.c_str());
  const Stack u = stack_of(u_, {3}, fn + ": increments");
  if (u.lead.size() != 1) throw py::value_error(fn + ": increments: expected an array of shape (N, 3), got " + shape_text(u.a));
  const py::ssize_t n = u.lead[0];
  const Stack z = rows_of(z_, n, {3}, fn + ": fixes");
  Ekf<Se2Odometry<double>, PlanarPoseFix<double>> ekf(Se2Odometry<double>(Se2OdometryNoise<double>{kxy, kts, ktt}),
                                                      PlanarPoseFix<double>(matrix_arg<3, 3>(R, fn + ": R")));
  return run<3, 3>(
      ekf, fn, "se2_odometry", x0, P0, n, std::vector<double>(std::size_t(n), 0.0),
      [&](py::ssize_t k) {
        const double* p = u.item(k);
        return SE2d(p[0], p[1], p[2]);
      },
      [&](py::ssize_t k) {
        const double* p = z.item(k);
        return PlanarPose<double>{p[0], p[1], p[2]};
      },
      mask_of(mask_, n, fn), gate);
}

template <class S>
py::tuple smooth(const EkfRun& r) {
  constexpr int D = DimOf<S>;
  const py::ssize_t n = r.states.shape(0);
  std::vector<SmootherStep<S>> steps(static_cast<std::size_t>(n));
  for (py::ssize_t k = 0; k < n; ++k) {
    SmootherStep<S>& s = steps[std::size_t(k)];
    s.predicted_mean = state_of<S>(read<D, 1>(r.predicted_states.data() + k * D));
    s.predicted_cov = read<D, D>(r.predicted_covariances.data() + k * D * D);
    s.F = read<D, D>(r.jacobians.data() + k * D * D);
    s.filtered_mean = state_of<S>(read<D, 1>(r.states.data() + k * D));
    s.filtered_cov = read<D, D>(r.covariances.data() + k * D * D);
  }
  const std::vector<Gaussian<S>> out = rts_smooth(steps);
  auto xs = make({n}, {D});
  auto Ps = make({n}, {D, D});
  for (py::ssize_t k = 0; k < n; ++k) {
    write<D, 1>(xs.mutable_data() + k * D, vec(out[std::size_t(k)].mean));
    write<D, D>(Ps.mutable_data() + k * D * D, out[std::size_t(k)].cov);
  }
  return py::make_tuple(xs, Ps);
}

py::tuple rts(const EkfRun& r) {
  require_numpy("rts_smooth");
  if (r.model == "seed000") return smooth<Eigen::Vector2d>(r);
  if (r.model == "constant_velocity") return smooth<Eigen::Vector4d>(r);
  return smooth<PlanarPose<double>>(r);
}

constexpr const char* kRunDoc =
    " Step k: predict from state k-1 (x0 for k = 0), then update with measurement k when mask[k] (default: every "
    "step). gate: NIS threshold of the update (inf: none). Raises ValueError with the C++ text for bad noise, x0 or "
    "P0 (e.g. 'Ekf::reset: ...'), and for a prediction or update that is not finite. Returns an EkfRun.";

}  // namespace

void bind_filters(py::module_& m) {
  py::class_<EkfRun>(m, "EkfRun",
                     "A recorded EKF run over N steps (each property returns a copy of the recorded array; D = state "
                     "dimension, M = measurement dimension).")
      .def_readonly("model", &EkfRun::model, "'seed000', 'constant_velocity', 'unicycle' or 'se2_odometry'")
      .def_property_readonly("states", [](const EkfRun& r) { return copy(r.states); }, "(N, D) filtered states")
      .def_property_readonly("covariances", [](const EkfRun& r) { return copy(r.covariances); }, "(N, D, D) filtered covariances")
      .def_property_readonly("predicted_states", [](const EkfRun& r) { return copy(r.predicted_states); }, "(N, D) predictions into step k")
      .def_property_readonly("predicted_covariances", [](const EkfRun& r) { return copy(r.predicted_covariances); }, "(N, D, D)")
      .def_property_readonly("jacobians", [](const EkfRun& r) { return copy(r.jacobians); }, "(N, D, D) F of the prediction into step k")
      .def_property_readonly("nis", [](const EkfRun& r) { return copy(r.nis); }, "(N,) normalised innovation squared (NaN where no update)")
      .def_property_readonly("innovations", [](const EkfRun& r) { return copy(r.innovations); }, "(N, M) innovations z (-) h(x) (NaN where no update)")
      .def_readonly("status", &EkfRun::status,
                    "per step: 'applied', 'rejected by gate', 'covariance not positive definite' or 'no measurement'")
      .def("__len__", [](const EkfRun& r) { return r.status.size(); }, "number of steps N")
      .def("__repr__", [](const EkfRun& r) {
        return "EkfRun(model='" + r.model + "', steps=" + std::to_string(r.status.size()) + ")";
      }, "Model and number of steps.");

  m.def("ekf_seed000", &ekf_seed000, py::arg("x0"), py::arg("P0"), py::arg("displacements"), py::arg("fixes"),
        py::arg("R"), py::arg("Q"), py::arg("mask") = py::none(), py::arg("gate") = std::numeric_limits<double>::infinity(),
        (std::string("Seed 000's EKF: state = road-plane position x0 (2,), P0 (2, 2); motion x' = x + u with "
                     "displacements (N, 2) and process noise R (2, 2); position fixes (N, 2) with noise Q (2, 2).") +
         kRunDoc)
            .c_str());
  m.def("ekf_constant_velocity", &ekf_cv, py::arg("x0"), py::arg("P0"), py::arg("dt"), py::arg("fixes"), py::arg("q"),
        py::arg("R"), py::arg("mask") = py::none(), py::arg("gate") = std::numeric_limits<double>::infinity(),
        (std::string("Constant-velocity EKF on the plane: state [px, py, vx, vy] x0 (4,), P0 (4, 4); white-noise "
                     "acceleration of spectral density q (m^2/s^3); dt (N,) or one number (s); position fixes (N, 2) "
                     "with noise R (2, 2).") +
         kRunDoc)
            .c_str());
  m.def("ekf_unicycle", &ekf_unicycle, py::arg("x0"), py::arg("P0"), py::arg("controls"), py::arg("dt"),
        py::arg("fixes"), py::arg("control_cov"), py::arg("R"), py::arg("integration") = "exact_arc",
        py::arg("mask") = py::none(), py::arg("gate") = std::numeric_limits<double>::infinity(),
        (std::string("Unicycle EKF: state [x, y, theta] x0 (3,), P0 (3, 3); controls (N, 2) [v m/s, w rad/s] over "
                     "dt (N,) or one number, with covariance control_cov (2, 2); integration 'exact_arc' or 'euler' "
                     "(seed 001 eq 10); pose fixes (N, 3) [x, y, theta] with noise R (3, 3).") +
         kRunDoc)
            .c_str());
  m.def("ekf_se2_odometry", &ekf_se2_odometry, py::arg("x0"), py::arg("P0"), py::arg("increments"), py::arg("fixes"),
        py::arg("R"), py::arg("xy_sigma_per_sqrt_m") = 0.02, py::arg("theta_sigma_per_sqrt_m") = 0.005,
        py::arg("theta_sigma_per_sqrt_rad") = 0.03, py::arg("mask") = py::none(),
        py::arg("gate") = std::numeric_limits<double>::infinity(),
        (std::string("SE(2)-odometry EKF: state [x, y, theta] x0 (3,), P0 (3, 3); body-frame odometry increments "
                     "(N, 3) [dx, dy, dtheta] composed on the pose, noise growing with distance and angle turned; "
                     "pose fixes (N, 3) with noise R (3, 3).") +
         kRunDoc)
            .c_str());
  m.def("rts_smooth", &rts, py::arg("run"),
        "Rauch-Tung-Striebel smoothing of an EkfRun: returns (states (N, D), covariances (N, D, D)), each estimate "
        "using the whole run. Raises ValueError when a predicted covariance is not positive definite.");
}

}  // namespace posefuse::python
