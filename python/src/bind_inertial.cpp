// posefuse.ImuNoise / Preintegration / preintegrate / ImuState / ImuFactor /
// align_visual_inertial: IMU pre-integration (inertial/) from numpy arrays.
//
// Stamps: an integer array is nanoseconds, a float array seconds (rounded to
// the nearest nanosecond), as core/samples.hpp stores them.
#include <pybind11/stl.h>

#include <Eigen/Core>
#include <array>
#include <cmath>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <posefuse/inertial/alignment.hpp>
#include <posefuse/inertial/imu_factor.hpp>
#include <posefuse/inertial/preintegrate.hpp>
#include <posefuse/inertial/preintegration.hpp>

#include "bindings.hpp"
#include "math_helpers.hpp"

namespace posefuse::python {
namespace {

namespace py = pybind11;
using namespace math;

constexpr int kMinKeyframes = 4;   // fewer: 6 (N-1) equations cannot fix 3N+4 unknowns

/// Seconds -> ns, refusing what int64 cannot hold.
std::int64_t to_ns(double t_s, const std::string& what) {
  if (!std::isfinite(t_s) || std::abs(t_s) > 9.2e9)
    throw invalid_argument(what + " is not a finite time in seconds within +-9.2e9 s");
  return std::llround(t_s * 1e9);
}

/// Stamps (n,) as ns: integers as they are, floats as seconds.
std::vector<std::int64_t> stamps_ns(const py::object& t, bool& seconds) {
  if (t.is_none()) throw py::type_error("preintegrate: t: expected an array of stamps, got None");
  py::array a = py::array::ensure(t);
  if (!a) {
    PyErr_Clear();
    throw py::type_error("preintegrate: t: cannot be converted to an array");
  }
  if (a.ndim() != 1) throw py::value_error("preintegrate: t: expected an array of shape (N,), got " + shape_text(a));
  const char kind = a.dtype().kind();
  std::vector<std::int64_t> out(std::size_t(a.shape(0)));
  if (kind == 'i' || kind == 'u') {
    seconds = false;
    auto i = py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>::ensure(a);
    std::copy(i.data(), i.data() + i.shape(0), out.begin());
  } else if (kind == 'f') {
    seconds = true;
    const Arr f = to_array(a, "preintegrate: t");
    for (std::size_t k = 0; k < out.size(); ++k) out[k] = to_ns(f.data()[k], "preintegrate: t[" + std::to_string(k) + "]");
  } else {
    throw py::type_error("preintegrate: t: expected integer (ns) or float (s) stamps, got dtype " +
                         std::string(py::str(a.dtype())));
  }
  return out;
}

ImuBias bias_of(const py::object& ba, const py::object& bg, const char* fn) {
  return ImuBias{matrix_arg<3, 1>(ba, std::string(fn) + ": bias_accel"),
                 matrix_arg<3, 1>(bg, std::string(fn) + ": bias_gyro")};
}

Preintegration preintegrate(const py::object& t_, const py::object& acc_, const py::object& gyro_,
                            const py::object& ba, const py::object& bg, const ImuNoise& noise, const py::object& t0_,
                            const py::object& t1_, double max_gap_s) {
  require_numpy("preintegrate");
  bool seconds = true;
  const std::vector<std::int64_t> t = stamps_ns(t_, seconds);
  const py::ssize_t n = py::ssize_t(t.size());
  const Stack acc = rows_of(acc_, n, {3}, "preintegrate: accel");
  const Stack gyro = rows_of(gyro_, n, {3}, "preintegrate: gyro");
  PreintegrationOptions opt;
  opt.max_gap_ns = to_ns(max_gap_s, "preintegrate: max_gap");
  opt.reserve_samples = std::size_t(n) + 2;
  Preintegration pre(noise, bias_of(ba, bg, "preintegrate"), opt);
  std::vector<ImuSample> samples(t.size());
  for (std::size_t k = 0; k < t.size(); ++k) {
    samples[k].t_ns = t[k];
    samples[k].accel_mps2 = read<3, 1>(acc.item(py::ssize_t(k)));
    samples[k].gyro_radps = read<3, 1>(gyro.item(py::ssize_t(k)));
  }
  const auto stamp = [&](const py::object& o, const char* what) -> std::int64_t {
    if (seconds) {
      if (!py::isinstance<py::float_>(o) && !py::isinstance<py::int_>(o) && !py::hasattr(o, "__float__"))
        throw py::type_error(std::string("preintegrate: ") + what + ": expected a time in seconds, like t");
      return to_ns(py::float_(o).cast<double>(), std::string("preintegrate: ") + what);
    }
    if (!py::hasattr(o, "__index__"))
      throw py::type_error(std::string("preintegrate: ") + what + ": expected an integer time in ns, like t");
    return py::int_(o).cast<std::int64_t>();
  };
  const auto sample_text = [&](std::size_t k) {
    return "sample " + std::to_string(k) + " (t = " + std::to_string(samples[k].t_ns) + " ns)";
  };
  if (!t0_.is_none() || !t1_.is_none()) {
    if (t0_.is_none() || t1_.is_none()) throw py::value_error("preintegrate: give both t0 and t1, or neither");
    for (std::size_t k = 1; k < samples.size(); ++k)  // preintegrate() binary-searches: the order must hold
      if (samples[k].t_ns <= samples[k - 1].t_ns)
        throw invalid_argument("preintegrate: " + sample_text(k) + ": " +
                               to_string(samples[k].t_ns < samples[k - 1].t_ns ? ImuStatus::kOutOfOrder
                                                                               : ImuStatus::kRepeated));
    const ImuStatus st = posefuse::preintegrate(samples, stamp(t0_, "t0"), stamp(t1_, "t1"), pre);
    if (st != ImuStatus::kApplied) throw invalid_argument(std::string("preintegrate: ") + to_string(st));
    return pre;
  }
  if (samples.size() < 2) throw invalid_argument("preintegrate: at least two samples are needed");
  for (std::size_t k = 0; k < samples.size(); ++k) {
    const ImuStatus st = pre.add(samples[k]);
    if (st != ImuStatus::kApplied && st != ImuStatus::kStarted)
      throw invalid_argument("preintegrate: " + sample_text(k) + ": " + to_string(st));
  }
  return pre;
}

py::object corrected(const Preintegration& p, const py::object& ba, const py::object& bg, bool jacobian) {
  require_numpy("Preintegration.corrected");
  const ImuBias b = bias_of(ba, bg, "Preintegration.corrected");
  if (!b.vector().allFinite()) throw invalid_argument("Preintegration.corrected: bias is not finite");
  Preintegration::BiasJacobian J;
  const ImuDelta d = p.delta(b, jacobian ? &J : nullptr);
  py::tuple out = jacobian ? py::tuple(4) : py::tuple(3);
  out[0] = to_numpy<3, 1>(d.p);
  out[1] = to_numpy<3, 3>(d.R.matrix());
  out[2] = to_numpy<3, 1>(d.v);
  if (jacobian) out[3] = to_numpy<9, 6>(J);
  return out;
}

// ---- ImuState ------------------------------------------------------------------

ImuState make_state(const py::object& p, const py::object& R, const py::object& v, const py::object& ba,
                    const py::object& bg) {
  require_numpy("ImuState");
  ImuState x;
  if (!p.is_none()) x.p = matrix_arg<3, 1>(p, "ImuState: p");
  if (!R.is_none()) x.R = SO3d(Eigen::Matrix3d(matrix_arg<3, 3>(R, "ImuState: R")));
  if (!v.is_none()) x.v = matrix_arg<3, 1>(v, "ImuState: v");
  if (!ba.is_none()) x.bias.accel = matrix_arg<3, 1>(ba, "ImuState: bias_accel");
  if (!bg.is_none()) x.bias.gyro = matrix_arg<3, 1>(bg, "ImuState: bias_gyro");
  if (!(x.p.allFinite() && x.v.allFinite() && x.bias.vector().allFinite()))
    throw invalid_argument("ImuState: p, v and the biases must be finite");
  return x;
}

py::object align_n(int n, const Stack& T, const SE3d& T_b_c, const std::vector<Preintegration>& pre_in,
                   const VisualInertialAlignmentOptions& opt) {
  std::vector<SE3d> poses(static_cast<std::size_t>(n));
  for (int k = 0; k < n; ++k) poses[std::size_t(k)] = se3_from_matrix(read<4, 4>(T.item(k)));
  std::vector<Preintegration> pre = pre_in;  // re-integrated copies; the caller's objects stay as they were
  const VisualInertialAlignmentResult r =
      align_visual_inertial(std::span<const SE3d>(poses), T_b_c, std::span<Preintegration>(pre), opt);
  py::dict d;
  d["status"] = std::string(to_string(r.status));
  d["ok"] = r.status == VisualInertialAlignmentStatus::kOk;
  d["scale"] = r.scale;
  d["gravity_c0"] = to_numpy<3, 1>(r.gravity_c0);
  d["gravity_norm_unrefined"] = r.gravity_norm_unrefined;
  d["accel_std"] = r.accel_std;
  d["gyro_bias"] = to_numpy<3, 1>(r.gyro_bias);
  auto vc0 = make({n}, {3}), vw = make({n}, {3}), Tw = make({n}, {4, 4});
  // Unsolved keyframes (a status other than ok) read as zero velocities and identity poses.
  for (int k = 0; k < n; ++k) {
    const std::size_t i = std::size_t(k);
    write<3, 1>(vc0.mutable_data() + 3 * k, i < r.velocity_c0.size() ? r.velocity_c0[i] : Eigen::Vector3d::Zero());
    write<3, 1>(vw.mutable_data() + 3 * k, i < r.velocity_w.size() ? r.velocity_w[i] : Eigen::Vector3d::Zero());
    write<4, 4>(Tw.mutable_data() + 16 * k, i < r.T_w_b.size() ? r.T_w_b[i].matrix() : SE3d().matrix());
  }
  d["velocity_c0"] = vc0;
  d["R_w_c0"] = to_numpy<3, 3>(r.R_w_c0.matrix());
  d["T_w_b"] = Tw;
  d["velocity_w"] = vw;
  d["preintegrations"] = py::cast(pre);
  return d;
}

py::object align(const py::object& T_, const py::object& Tbc_, const std::vector<Preintegration>& pre, double G,
                 double min_accel_std, double max_gravity_norm_error, int refinement_iterations) {
  require_numpy("align_visual_inertial");
  const Stack T = stack_of(T_, {4, 4}, "align_visual_inertial: T_c0_c");
  if (T.lead.size() != 1) throw py::value_error("align_visual_inertial: T_c0_c: expected an array of shape (N, 4, 4), got " + shape_text(T.a));
  const int n = int(T.lead[0]);
  if (n < kMinKeyframes)
    throw py::value_error("align_visual_inertial: " + std::to_string(n) + " keyframes; at least " +
                          std::to_string(kMinKeyframes) + " are needed");
  if (int(pre.size()) != n - 1)
    throw py::value_error("align_visual_inertial: " + std::to_string(n) + " keyframes need " + std::to_string(n - 1) +
                          " pre-integrations, got " + std::to_string(pre.size()));
  const SE3d T_b_c = se3_from_matrix(matrix_arg<4, 4>(Tbc_, "align_visual_inertial: T_b_c"));
  VisualInertialAlignmentOptions opt;
  opt.gravity_norm = finite(G, "align_visual_inertial: gravity_norm");
  opt.min_accel_std = finite(min_accel_std, "align_visual_inertial: min_accel_std");
  opt.max_gravity_norm_error = finite(max_gravity_norm_error, "align_visual_inertial: max_gravity_norm_error");
  if (refinement_iterations < 0) throw py::value_error("align_visual_inertial: refinement_iterations must be >= 0");
  opt.refinement_iterations = refinement_iterations;
  return align_n(n, T, T_b_c, pre, opt);
}

}  // namespace

void bind_inertial(py::module_& m) {
  py::class_<ImuNoise>(m, "ImuNoise",
                       "Continuous-time IMU noise figures (the four numbers of a Kalibr / EuRoC imu.yaml); defaults: "
                       "EuRoC's ADIS16448.")
      .def(py::init([](double gn, double an, double grw, double arw) {
             ImuNoise n{gn, an, grw, arw};
             n.validate();
             return n;
           }),
           py::arg("gyro_noise_density") = 1.6968e-4, py::arg("accel_noise_density") = 2.0e-3,
           py::arg("gyro_random_walk") = 1.9393e-5, py::arg("accel_random_walk") = 3.0e-3,
           "Raises ValueError naming the first figure that is negative or not finite.")
      .def_readwrite("gyro_noise_density", &ImuNoise::gyro_noise_density, "sigma_g (rad/s/sqrt(Hz))")
      .def_readwrite("accel_noise_density", &ImuNoise::accel_noise_density, "sigma_a (m/s^2/sqrt(Hz))")
      .def_readwrite("gyro_random_walk", &ImuNoise::gyro_random_walk, "sigma_bg (rad/s^2/sqrt(Hz))")
      .def_readwrite("accel_random_walk", &ImuNoise::accel_random_walk, "sigma_ba (m/s^3/sqrt(Hz))")
      .def("__repr__", [](const ImuNoise& n) {
        return "ImuNoise(gyro_noise_density=" + std::string(py::repr(py::float_(n.gyro_noise_density))) +
               ", accel_noise_density=" + std::string(py::repr(py::float_(n.accel_noise_density))) +
               ", gyro_random_walk=" + std::string(py::repr(py::float_(n.gyro_random_walk))) +
               ", accel_random_walk=" + std::string(py::repr(py::float_(n.accel_random_walk))) + ")";
      }, "All four figures.");

  py::class_<Preintegration>(
      m, "Preintegration",
      "IMU pre-integration between two keyframes i and j in the body frame of i (mid-point rule, VINS-Mono; "
      "Forster et al. 2017): delta_R = R_i^T R_j, delta_v, delta_p, the 15x15 covariance over [dp, dphi, dv, dba, "
      "dbg] and the bias Jacobians. Made by preintegrate().")
      .def_property_readonly("delta_p", [](const Preintegration& p) { return to_numpy<3, 1>(p.delta().p); },
                             "Delta p_ij (3,), m, frame i")
      .def_property_readonly("delta_R", [](const Preintegration& p) { return to_numpy<3, 3>(p.delta().R.matrix()); },
                             "Delta R_ij = R_i^T R_j (3, 3)")
      .def_property_readonly("delta_v", [](const Preintegration& p) { return to_numpy<3, 1>(p.delta().v); },
                             "Delta v_ij (3,), m/s, frame i")
      .def_property_readonly("dt", &Preintegration::dt_s, "Delta t_ij (s): sum of the integrated steps")
      .def_property_readonly("covariance", [](const Preintegration& p) { return to_numpy<15, 15>(p.covariance()); },
                             "(15, 15) covariance of [dp, dphi, dv, dba, dbg] (dphi the right perturbation of delta_R)")
      .def_property_readonly("bias_jacobian",
                             [](const Preintegration& p) { return to_numpy<9, 6>(p.bias_jacobian()); },
                             "(9, 6) d[delta_p, delta_phi, delta_v] / d[b_a, b_g] at the linearisation bias")
      .def_property_readonly("bias_accel", [](const Preintegration& p) { return to_numpy<3, 1>(p.bias().accel); },
                             "linearisation accelerometer bias (3,)")
      .def_property_readonly("bias_gyro", [](const Preintegration& p) { return to_numpy<3, 1>(p.bias().gyro); },
                             "linearisation gyroscope bias (3,)")
      .def_property_readonly("noise", &Preintegration::noise, "the ImuNoise figures")
      .def_property_readonly("sample_count", &Preintegration::sample_count, "stored samples (steps + 1)")
      .def_property_readonly("start_t_ns", &Preintegration::start_t_ns, "stamp of the first sample (ns)")
      .def_property_readonly("end_t_ns", &Preintegration::end_t_ns, "stamp of the last sample (ns)")
      .def("corrected", &corrected, py::arg("bias_accel"), py::arg("bias_gyro"), py::arg("jacobian") = false,
           "The first-order bias-corrected measurement (Forster eq 44) for another bias: (delta_p, delta_R, "
           "delta_v), and with jacobian=True the (9, 6) Jacobian of [dp, dphi, dv] w.r.t. [b_a, b_g].")
      .def(
          "update_bias",
          [](Preintegration& p, const py::object& ba, const py::object& bg) {
            return p.update_bias(bias_of(ba, bg, "Preintegration.update_bias"));
          },
          py::arg("bias_accel"), py::arg("bias_gyro"),
          "Moves the linearisation bias: re-integrates when the change exceeds 0.1 m/s^2 or 0.01 rad/s; returns "
          "True when it did.")
      .def(
          "reintegrate",
          [](Preintegration& p, const py::object& ba, const py::object& bg) {
            p.reintegrate(bias_of(ba, bg, "Preintegration.reintegrate"));
          },
          py::arg("bias_accel"), py::arg("bias_gyro"), "Re-integrates every stored sample about a new bias.")
      .def("__repr__", [](const Preintegration& p) {
        return "Preintegration(dt=" + std::string(py::repr(py::float_(p.dt_s()))) +
               ", sample_count=" + std::to_string(p.sample_count()) + ")";
      }, "Interval length and sample count.");

  m.def("preintegrate", &preintegrate, py::arg("t"), py::arg("accel"), py::arg("gyro"),
        py::arg("bias_accel") = std::array<double, 3>{0, 0, 0}, py::arg("bias_gyro") = std::array<double, 3>{0, 0, 0},
        py::arg("noise") = ImuNoise{}, py::arg("t0") = py::none(), py::arg("t1") = py::none(),
        py::arg("max_gap") = 0.05,
        "Pre-integrates IMU samples: stamps t (N,) (int = ns, float = s), accel (N, 3) specific force (m/s^2), "
        "gyro (N, 3) (rad/s), about the linearisation biases, with the noise figures. Without t0/t1 every sample "
        "is integrated; with them (same unit as t) the interval [t0, t1] is cut from the stream, the end samples "
        "linearly interpolated. max_gap (s) is the largest accepted time between samples. A sample out of order, "
        "repeated, after a gap or not finite raises ValueError naming it. Returns a Preintegration.");

  py::class_<ImuState>(m, "ImuState",
                       "A keyframe state [p, R, v, b_a, b_g] (world frame, z up; body = IMU frame) with tangent [dp, "
                       "dphi, dv, dba, dbg] (dp world frame, R (+) dphi = R Exp(dphi)).")
      .def(py::init(&make_state), py::arg("p") = py::none(), py::arg("R") = py::none(), py::arg("v") = py::none(),
           py::arg("bias_accel") = py::none(), py::arg("bias_gyro") = py::none(),
           "p (3,) m, R (3, 3) body -> world (validated as SO3), v (3,) m/s, biases (3,); omitted = zero / identity.")
      .def_property_readonly("p", [](const ImuState& x) { return to_numpy<3, 1>(x.p); }, "position (3,)")
      .def_property_readonly("R", [](const ImuState& x) { return to_numpy<3, 3>(x.R.matrix()); }, "attitude (3, 3)")
      .def_property_readonly("v", [](const ImuState& x) { return to_numpy<3, 1>(x.v); }, "velocity (3,)")
      .def_property_readonly("bias_accel", [](const ImuState& x) { return to_numpy<3, 1>(x.bias.accel); }, "(3,)")
      .def_property_readonly("bias_gyro", [](const ImuState& x) { return to_numpy<3, 1>(x.bias.gyro); }, "(3,)")
      .def(
          "plus",
          [](const ImuState& x, const py::object& d) {
            require_numpy("ImuState.plus");
            return x.plus(matrix_arg<15, 1>(d, "ImuState.plus: d"));
          },
          py::arg("d"), "x (+) d for d (15,) [dp, dphi, dv, dba, dbg].")
      .def(
          "minus", [](const ImuState& y, const ImuState& x) { return to_numpy<15, 1>(y.minus(x)); }, py::arg("x"),
          "y (-) x (15,) (this = y).")
      .def(
          "__repr__",
          [](const ImuState& x) {
            const auto v3 = [](const Eigen::Vector3d& v) {
              return "[" + std::string(py::repr(py::float_(v.x()))) + ", " + std::string(py::repr(py::float_(v.y()))) +
                     ", " + std::string(py::repr(py::float_(v.z()))) + "]";
            };
            return "ImuState(p=" + v3(x.p) + ", phi=" + v3(x.R.log()) + ", v=" + v3(x.v) + ", bias_accel=" +
                   v3(x.bias.accel) + ", bias_gyro=" + v3(x.bias.gyro) + ")";
          },
          "The state, attitude as its rotation vector phi.");

  py::class_<ImuFactor>(m, "ImuFactor",
                        "The IMU factor of one pre-integrated interval (Forster et al. 2017 eq 45; VINS-Mono eq 16): "
                        "residual [r_p, r_phi, r_v, r_ba, r_bg] between two ImuStates, analytic Jacobians, whitening "
                        "by the pre-integration covariance.")
      .def(py::init([](const Preintegration& pre, const py::object& g) {
             require_numpy("ImuFactor");
             return ImuFactor(pre, matrix_arg<3, 1>(g, "ImuFactor: gravity"));
           }),
           py::arg("preintegration"), py::arg("gravity") = std::array<double, 3>{0.0, 0.0, -9.81},
           "gravity: the gravity vector in the world frame (m/s^2). Raises ValueError when the pre-integration has no "
           "step, gravity is not finite or the covariance is not positive definite (C++ messages).")
      .def(
          "residual",
          [](const ImuFactor& f, const ImuState& xi, const ImuState& xj, bool jacobians, bool whitened) -> py::object {
            ImuFactor::Jacobian Ji, Jj;
            const ImuFactor::Residual r = whitened ? f.whitened_residual(xi, xj, jacobians ? &Ji : nullptr,
                                                                         jacobians ? &Jj : nullptr)
                                                   : f.residual(xi, xj, jacobians ? &Ji : nullptr,
                                                                jacobians ? &Jj : nullptr);
            if (!jacobians) return to_numpy<15, 1>(r);
            return py::make_tuple(to_numpy<15, 1>(r), to_numpy<15, 15>(Ji), to_numpy<15, 15>(Jj));
          },
          py::arg("xi"), py::arg("xj"), py::arg("jacobians") = false, py::arg("whitened") = false,
          "r (15,) = [r_p, r_phi, r_v, r_ba, r_bg]; whitened=True gives L^-1 r (P = L L^T). With jacobians=True "
          "returns (r, J_r_i (15, 15), J_r_j (15, 15)) (right perturbations; whitened when asked).")
      .def("predict", &ImuFactor::predict<>, py::arg("xi"),
           "The state j predicted from state i (the residual is then zero).")
      .def_property_readonly("covariance", [](const ImuFactor& f) { return to_numpy<15, 15>(f.covariance()); },
                             "the pre-integration covariance P (15, 15)")
      .def_property_readonly("whitening", [](const ImuFactor& f) { return to_numpy<15, 15>(f.whitening()); },
                             "L^-1 (15, 15), lower triangular, P = L L^T")
      .def_property_readonly("dt", &ImuFactor::dt_s, "Delta t (s)");

  m.def("align_visual_inertial", &align, py::arg("T_c0_c"), py::arg("T_b_c"), py::arg("preintegrations"),
        py::arg("gravity_norm") = 9.81, py::arg("min_accel_std") = 0.25, py::arg("max_gravity_norm_error") = 1.0,
        py::arg("refinement_iterations") = 4,
        "Visual-inertial alignment (VINS-Mono's initialisation) of N keyframes (3 <= N <= 8): up-to-scale camera "
        "poses T_c0_c (N, 4, 4) in the first camera's frame, the camera-IMU extrinsic T_b_c (4, 4) and the N - 1 "
        "Preintegrations between consecutive keyframes. Estimates the gyroscope bias, the scale, gravity and the "
        "velocities, then rotates into a z-up world. Returns a dict: status ('ok', 'insufficient excitation', "
        "'solve failed', 'non-positive scale', 'gravity norm off'), ok, scale, gravity_c0 (3,), "
        "gravity_norm_unrefined, accel_std, gyro_bias (3,), velocity_c0 (N, 3), R_w_c0 (3, 3), T_w_b (N, 4, 4), "
        "velocity_w (N, 3), preintegrations (re-integrated copies; the inputs are not modified). Outputs are valid "
        "only when ok.");
}

}  // namespace posefuse::python
