// posefuse.SO2 / SE2 / SO3 / SE3: the Lie groups of lie/ as namespaces of
// static functions over numpy stacks of matrices (any leading shape).
//
// Elements are matrices: SO2 (..., 2, 2), SE2 (..., 3, 3), SO3 (..., 3, 3),
// SE3 (..., 4, 4). Tangents: SO2 (...) angles, SE2 (..., 3), SO3 (..., 3),
// SE3 (..., 6), translation part first (lie/lie.hpp). Elements are
// validated and projected as the C++ constructors from external
// representations do; tangents and points are not (NaN in, NaN out).
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <string>

#include <posefuse/lie/lie.hpp>

#include "bindings.hpp"
#include "math_helpers.hpp"

namespace posefuse::python {
namespace {

namespace py = pybind11;
using namespace math;

/// Tolerance of the matrix checks (SO3's default orthonormality tolerance).
constexpr double kTol = SO3d::kDefaultOrthonormalityTolerance;

template <class G>
struct Traits;

template <>
struct Traits<SO2d> {
  static constexpr const char* name = "SO2";
  static constexpr int M = 2, D = 1, P = 2;
  static Shape tangent() { return {}; }
  static SO2d from(const double* p) {
    const Eigen::Matrix2d R = read<2, 2>(p);
    if (!R.allFinite()) throw invalid_argument("SO2: rotation matrix has a non-finite entry");
    const double err = (R.transpose() * R - Eigen::Matrix2d::Identity()).cwiseAbs().maxCoeff();
    if (!(err <= kTol))
      throw invalid_argument("SO2: matrix is not orthonormal (max |R^T R - I| = " + std::to_string(err) + " > " +
                             std::to_string(kTol) + ")");
    if (!(R.determinant() > 0)) throw invalid_argument("SO2: matrix is a reflection (det <= 0), not a rotation");
    return SO2d::from_cos_sin(R(0, 0), R(1, 0));
  }
  static void to(const SO2d& g, double* p) { write<2, 2>(p, g.matrix()); }
};

template <>
struct Traits<SE2d> {
  static constexpr const char* name = "SE2";
  static constexpr int M = 3, D = 3, P = 2;
  static Shape tangent() { return {3}; }
  static SE2d from(const double* p) {
    const Eigen::Matrix3d T = read<3, 3>(p);
    if (!((T.row(2) - Eigen::RowVector3d(0, 0, 1)).cwiseAbs().maxCoeff() <= kTol))
      throw invalid_argument("SE2: bottom row of the matrix is not [0 0 1]");
    const double rm[4] = {T(0, 0), T(0, 1), T(1, 0), T(1, 1)};
    const SO2d R = Traits<SO2d>::from(rm);
    if (!(std::isfinite(T(0, 2)) && std::isfinite(T(1, 2))))
      throw invalid_argument("SE2: translation has a non-finite entry");
    return SE2d(Eigen::Vector2d(T(0, 2), T(1, 2)), R);
  }
  static void to(const SE2d& g, double* p) { write<3, 3>(p, g.matrix()); }
};

template <>
struct Traits<SO3d> {
  static constexpr const char* name = "SO3";
  static constexpr int M = 3, D = 3, P = 3;
  static Shape tangent() { return {3}; }
  static SO3d from(const double* p) { return SO3d(Eigen::Matrix3d(read<3, 3>(p))); }
  static void to(const SO3d& g, double* p) { write<3, 3>(p, g.matrix()); }
};

template <>
struct Traits<SE3d> {
  static constexpr const char* name = "SE3";
  static constexpr int M = 4, D = 6, P = 3;
  static Shape tangent() { return {6}; }
  static SE3d from(const double* p) { return se3_from_matrix(read<4, 4>(p)); }
  static void to(const SE3d& g, double* p) { write<4, 4>(p, g.matrix()); }
};

template <class G>
struct Ops {
  using Tr = Traits<G>;
  static constexpr int M = Tr::M, D = Tr::D, P = Tr::P;
  using Tangent = typename G::Tangent;
  using Jac = typename G::Jacobian;

  static std::string fn(const char* f) { return std::string(Tr::name) + "." + f; }
  static Shape mat() { return {M, M}; }
  static Shape jac() { return {D, D}; }
  static Stack elements(const py::object& o, const char* f, const char* arg) {
    require_numpy(fn(f).c_str());
    return stack_of(o, mat(), fn(f) + ": " + arg);
  }
  static Stack tangents(const py::object& o, const char* f, const char* arg) {
    require_numpy(fn(f).c_str());
    return stack_of(o, Tr::tangent(), fn(f) + ": " + arg);
  }
  static Tangent tan(const double* p) { return Eigen::Map<const Tangent>(p); }
  static void put_tan(double* p, const Tangent& t) {
    Eigen::Map<Tangent> dst(p);
    dst = t;
  }

  static py::object exp(const py::object& tau, bool jacobian) {
    const Stack t = tangents(tau, "exp", "tau");
    auto out = make(t.lead, mat());
    py::array_t<double> J = jacobian ? make(t.lead, jac()) : py::array_t<double>();
    for (py::ssize_t i = 0; i < t.n; ++i) {
      Jac Ji;
      const G g = G::exp(tan(t.item(i)), jacobian ? &Ji : nullptr);
      Tr::to(g, out.mutable_data() + i * M * M);
      if (jacobian) write<D, D>(J.mutable_data() + i * D * D, Ji);
    }
    if (jacobian) return py::make_tuple(out, J);
    return out;
  }

  static py::object log(const py::object& g_, bool jacobian) {
    const Stack g = elements(g_, "log", "g");
    auto out = make(g.lead, Tr::tangent());
    py::array_t<double> J = jacobian ? make(g.lead, jac()) : py::array_t<double>();
    for (py::ssize_t i = 0; i < g.n; ++i) {
      Jac Ji;
      put_tan(out.mutable_data() + i * D, Tr::from(g.item(i)).log(jacobian ? &Ji : nullptr));
      if (jacobian) write<D, D>(J.mutable_data() + i * D * D, Ji);
    }
    if (jacobian) return py::make_tuple(out, J);
    return out;
  }

  static py::object inverse(const py::object& g_, bool jacobian) {
    const Stack g = elements(g_, "inverse", "g");
    auto out = make(g.lead, mat());
    py::array_t<double> J = jacobian ? make(g.lead, jac()) : py::array_t<double>();
    for (py::ssize_t i = 0; i < g.n; ++i) {
      Jac Ji;
      Tr::to(Tr::from(g.item(i)).inverse(jacobian ? &Ji : nullptr), out.mutable_data() + i * M * M);
      if (jacobian) write<D, D>(J.mutable_data() + i * D * D, Ji);
    }
    if (jacobian) return py::make_tuple(out, J);
    return out;
  }

  /// compose / between: c = op(a, b) with J_c_a, J_c_b.
  template <bool Between>
  static py::object binary(const py::object& a_, const py::object& b_, bool jacobians) {
    const char* f = Between ? "between" : "compose";
    const Stack a = elements(a_, f, "a");
    const Stack b = elements(b_, f, "b");
    const Shape lead = broadcast(a, b, fn(f));
    const py::ssize_t n = count(lead);
    auto out = make(lead, mat());
    py::array_t<double> Ja = jacobians ? make(lead, jac()) : py::array_t<double>();
    py::array_t<double> Jb = jacobians ? make(lead, jac()) : py::array_t<double>();
    for (py::ssize_t i = 0; i < n; ++i) {
      Jac J1, J2;
      const G ga = Tr::from(a.item(i)), gb = Tr::from(b.item(i));
      const G c = Between ? ga.between(gb, jacobians ? &J1 : nullptr, jacobians ? &J2 : nullptr)
                          : ga.compose(gb, jacobians ? &J1 : nullptr, jacobians ? &J2 : nullptr);
      Tr::to(c, out.mutable_data() + i * M * M);
      if (jacobians) {
        write<D, D>(Ja.mutable_data() + i * D * D, J1);
        write<D, D>(Jb.mutable_data() + i * D * D, J2);
      }
    }
    if (jacobians) return py::make_tuple(out, Ja, Jb);
    return out;
  }

  static py::object act(const py::object& g_, const py::object& p_, bool jacobians) {
    const Stack g = elements(g_, "act", "g");
    const Stack p = stack_of(p_, {P}, fn("act") + ": p");
    const Shape lead = broadcast(g, p, fn("act"));
    const py::ssize_t n = count(lead);
    auto out = make(lead, {P});
    py::array_t<double> Jg = jacobians ? make(lead, {P, D}) : py::array_t<double>();
    py::array_t<double> Jp = jacobians ? make(lead, {P, P}) : py::array_t<double>();
    for (py::ssize_t i = 0; i < n; ++i) {
      typename G::ActJacobianGroup J1;
      typename G::ActJacobianPoint J2;
      const typename G::Point q = Tr::from(g.item(i)).act(Eigen::Map<const typename G::Point>(p.item(i)),
                                                           jacobians ? &J1 : nullptr, jacobians ? &J2 : nullptr);
      Eigen::Map<typename G::Point> dst(out.mutable_data() + i * P);
      dst = q;
      if (jacobians) {
        write<P, D>(Jg.mutable_data() + i * P * D, J1);
        write<P, P>(Jp.mutable_data() + i * P * P, J2);
      }
    }
    if (jacobians) return py::make_tuple(out, Jg, Jp);
    return out;
  }

  static py::object plus(const py::object& x_, const py::object& tau_, bool jacobians) {
    const Stack x = elements(x_, "plus", "x");
    const Stack t = tangents(tau_, "plus", "tau");
    const Shape lead = broadcast(x, t, fn("plus"));
    const py::ssize_t n = count(lead);
    auto out = make(lead, mat());
    py::array_t<double> Jx = jacobians ? make(lead, jac()) : py::array_t<double>();
    py::array_t<double> Jt = jacobians ? make(lead, jac()) : py::array_t<double>();
    for (py::ssize_t i = 0; i < n; ++i) {
      Jac J1, J2;
      const G y = Tr::from(x.item(i)).plus(tan(t.item(i)), jacobians ? &J1 : nullptr, jacobians ? &J2 : nullptr);
      Tr::to(y, out.mutable_data() + i * M * M);
      if (jacobians) {
        write<D, D>(Jx.mutable_data() + i * D * D, J1);
        write<D, D>(Jt.mutable_data() + i * D * D, J2);
      }
    }
    if (jacobians) return py::make_tuple(out, Jx, Jt);
    return out;
  }

  static py::object minus(const py::object& y_, const py::object& x_, bool jacobians) {
    const Stack y = elements(y_, "minus", "y");
    const Stack x = elements(x_, "minus", "x");
    const Shape lead = broadcast(y, x, fn("minus"));
    const py::ssize_t n = count(lead);
    auto out = make(lead, Tr::tangent());
    py::array_t<double> Jy = jacobians ? make(lead, jac()) : py::array_t<double>();
    py::array_t<double> Jx = jacobians ? make(lead, jac()) : py::array_t<double>();
    for (py::ssize_t i = 0; i < n; ++i) {
      Jac J1, J2;
      put_tan(out.mutable_data() + i * D,
              Tr::from(y.item(i)).minus(Tr::from(x.item(i)), jacobians ? &J1 : nullptr, jacobians ? &J2 : nullptr));
      if (jacobians) {
        write<D, D>(Jy.mutable_data() + i * D * D, J1);
        write<D, D>(Jx.mutable_data() + i * D * D, J2);
      }
    }
    if (jacobians) return py::make_tuple(out, Jy, Jx);
    return out;
  }

  static py::array_t<double> adjoint(const py::object& g_) {
    const Stack g = elements(g_, "adjoint", "g");
    auto out = make(g.lead, jac());
    for (py::ssize_t i = 0; i < g.n; ++i) write<D, D>(out.mutable_data() + i * D * D, Tr::from(g.item(i)).adjoint());
    return out;
  }

  template <Jac (*F)(const Tangent&)>
  static py::array_t<double> tangent_matrix(const py::object& tau, const char* f) {
    const Stack t = tangents(tau, f, "tau");
    auto out = make(t.lead, jac());
    for (py::ssize_t i = 0; i < t.n; ++i) write<D, D>(out.mutable_data() + i * D * D, F(tan(t.item(i))));
    return out;
  }

  static py::array_t<double> hat(const py::object& tau) {
    const Stack t = tangents(tau, "hat", "tau");
    auto out = make(t.lead, mat());
    for (py::ssize_t i = 0; i < t.n; ++i) write<M, M>(out.mutable_data() + i * M * M, G::hat(tan(t.item(i))));
    return out;
  }

  static py::array_t<double> vee(const py::object& W_) {
    const Stack W = elements(W_, "vee", "W");
    auto out = make(W.lead, Tr::tangent());
    for (py::ssize_t i = 0; i < W.n; ++i) put_tan(out.mutable_data() + i * D, G::vee(read<M, M>(W.item(i))));
    return out;
  }

  static py::array_t<double> normalize(const py::object& g_) {
    const Stack g = elements(g_, "normalize", "g");
    auto out = make(g.lead, mat());
    for (py::ssize_t i = 0; i < g.n; ++i) Tr::to(Tr::from(g.item(i)), out.mutable_data() + i * M * M);
    return out;
  }

  static py::array_t<double> identity() {
    require_numpy(fn("identity").c_str());
    auto out = make({}, mat());
    Tr::to(G::identity(), out.mutable_data());
    return out;
  }

  template <class Tag>
  static py::class_<Tag> bind(py::module_& m, const char* doc, const char* tangent_doc, const char* point_doc) {
    py::class_<Tag> c(m, Tr::name, doc);
    const std::string T = tangent_doc, E = std::string(Tr::name) + " elements as (..., " + std::to_string(M) + ", " +
                                              std::to_string(M) + ") matrices";
    const std::string Jd = "(..., " + std::to_string(D) + ", " + std::to_string(D) + ")";
    const auto d = [](const std::string& s) { return s; };
    c.def_static("exp", &exp, py::arg("tau"), py::arg("jacobian") = false,
                 ("Exp(tau): the element of tangent vectors tau " + T +
                  ". With jacobian=True returns (g, Jr(tau)), Jr " + Jd + ".")
                     .c_str());
    c.def_static("log", &log, py::arg("g"), py::arg("jacobian") = false,
                 ("Log(g) of " + E + ": tangent vectors " + T +
                  ", rotation angle in [0, pi] (SO2/SE2: theta in [-pi, pi)). With jacobian=True returns "
                  "(tau, Jr^-1(tau)).")
                     .c_str());
    c.def_static("inverse", &inverse, py::arg("g"), py::arg("jacobian") = false,
                 ("g^-1 of " + E + ". With jacobian=True returns (g^-1, -Ad_g).").c_str());
    c.def_static("compose", &binary<false>, py::arg("a"), py::arg("b"), py::arg("jacobians") = false,
                 ("a b (" + E +
                  "; equal leading shapes, or one single element). With jacobians=True returns (c, J_c_a, J_c_b).")
                     .c_str());
    c.def_static("between", &binary<true>, py::arg("a"), py::arg("b"), py::arg("jacobians") = false,
                 ("a^-1 b, b expressed in a (" + E + "). With jacobians=True returns (d, J_d_a, J_d_b).").c_str());
    c.def_static("act", &act, py::arg("g"), py::arg("p"), py::arg("jacobians") = false,
                 ("g p: points " + std::string(point_doc) +
                  " mapped by g (body to world). With jacobians=True returns (q, J_q_g, J_q_p).")
                     .c_str());
    c.def_static("plus", &plus, py::arg("x"), py::arg("tau"), py::arg("jacobians") = false,
                 "x (+) tau = x Exp(tau) (right perturbation). With jacobians=True returns (y, J_y_x, J_y_tau).");
    c.def_static("minus", &minus, py::arg("y"), py::arg("x"), py::arg("jacobians") = false,
                 ("y (-) x = Log(x^-1 y), tangent " + T + ". With jacobians=True returns (d, J_d_y, J_d_x).").c_str());
    c.def_static("adjoint", &adjoint, py::arg("g"), ("Ad_g " + Jd + ": g Exp(tau) = Exp(Ad_g tau) g.").c_str());
    c.def_static("right_jacobian", [](const py::object& t) { return tangent_matrix<&G::right_jacobian>(t, "right_jacobian"); },
                 py::arg("tau"), ("Right Jacobian Jr(tau) " + Jd + ".").c_str());
    c.def_static("right_jacobian_inverse",
                 [](const py::object& t) { return tangent_matrix<&G::right_jacobian_inverse>(t, "right_jacobian_inverse"); },
                 py::arg("tau"), ("Jr(tau)^-1 " + Jd + ".").c_str());
    c.def_static("left_jacobian", [](const py::object& t) { return tangent_matrix<&G::left_jacobian>(t, "left_jacobian"); },
                 py::arg("tau"), ("Left Jacobian Jl(tau) = Jr(-tau) " + Jd + ".").c_str());
    c.def_static("left_jacobian_inverse",
                 [](const py::object& t) { return tangent_matrix<&G::left_jacobian_inverse>(t, "left_jacobian_inverse"); },
                 py::arg("tau"), ("Jl(tau)^-1 " + Jd + ".").c_str());
    c.def_static("hat", &hat, py::arg("tau"), d("tau^ : the Lie-algebra matrix of tangent vectors " + T + ".").c_str());
    c.def_static("vee", &vee, py::arg("W"), "Inverse of hat (the antisymmetric part of the rotation block).");
    c.def_static("normalize", &normalize, py::arg("g"),
                 ("The nearest valid element of each matrix (checked within 1e-5 and projected, as the C++ "
                  "constructors from matrices): " +
                  E + ".")
                     .c_str());
    c.def_static("identity", &identity, "The identity element as a matrix.");
    return c;
  }
};

struct SO2Tag {};
struct SE2Tag {};
struct SO3Tag {};
struct SE3Tag {};

// ---- extras -----------------------------------------------------------------

py::array_t<double> so3_from_quaternion(const py::object& q_, const std::string& order) {
  require_numpy("SO3.from_quaternion");
  if (order != "wxyz" && order != "xyzw")
    throw py::value_error("SO3.from_quaternion: order must be 'wxyz' or 'xyzw', got '" + order + "'");
  const Stack q = stack_of(q_, {4}, "SO3.from_quaternion: q");
  auto out = make(q.lead, {3, 3});
  const bool w_first = order == "wxyz";
  for (py::ssize_t i = 0; i < q.n; ++i) {
    const double* p = q.item(i);
    const Eigen::Quaterniond Q = w_first ? Eigen::Quaterniond(p[0], p[1], p[2], p[3])
                                         : Eigen::Quaterniond(p[3], p[0], p[1], p[2]);
    write<3, 3>(out.mutable_data() + i * 9, SO3d(Q).matrix());
  }
  return out;
}

py::array_t<double> so3_to_quaternion(const py::object& R_, const std::string& order) {
  require_numpy("SO3.to_quaternion");
  if (order != "wxyz" && order != "xyzw")
    throw py::value_error("SO3.to_quaternion: order must be 'wxyz' or 'xyzw', got '" + order + "'");
  const Stack R = stack_of(R_, {3, 3}, "SO3.to_quaternion: R");
  auto out = make(R.lead, {4});
  for (py::ssize_t i = 0; i < R.n; ++i) {
    Eigen::Quaterniond Q = Traits<SO3d>::from(R.item(i)).quaternion();
    if (Q.w() < 0) Q.coeffs() = -Q.coeffs();
    double* o = out.mutable_data() + i * 4;
    if (order == "wxyz") {
      o[0] = Q.w(), o[1] = Q.x(), o[2] = Q.y(), o[3] = Q.z();
    } else {
      o[0] = Q.x(), o[1] = Q.y(), o[2] = Q.z(), o[3] = Q.w();
    }
  }
  return out;
}

py::array_t<double> se3_from_rt(const py::object& R_, const py::object& t_) {
  require_numpy("SE3.from_rt");
  const Stack R = stack_of(R_, {3, 3}, "SE3.from_rt: R");
  const Stack t = stack_of(t_, {3}, "SE3.from_rt: t");
  const Shape lead = broadcast(R, t, "SE3.from_rt");
  const py::ssize_t n = count(lead);
  auto out = make(lead, {4, 4});
  for (py::ssize_t i = 0; i < n; ++i) {
    const Eigen::Vector3d tv = read<3, 1>(t.item(i));
    if (!tv.allFinite()) throw invalid_argument("SE3: translation has a non-finite entry");
    write<4, 4>(out.mutable_data() + i * 16, SE3d(tv, Traits<SO3d>::from(R.item(i))).matrix());
  }
  return out;
}

py::array_t<double> se2_from_xytheta(const py::object& x_) {
  require_numpy("SE2.from_xytheta");
  const Stack x = stack_of(x_, {3}, "SE2.from_xytheta: pose");
  auto out = make(x.lead, {3, 3});
  for (py::ssize_t i = 0; i < x.n; ++i) {
    const double* p = x.item(i);
    if (!(std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2])))
      throw py::value_error("SE2.from_xytheta: pose " + std::to_string(i) + " is not finite");
    write<3, 3>(out.mutable_data() + i * 9, SE2d(p[0], p[1], p[2]).matrix());
  }
  return out;
}

py::array_t<double> se2_to_xytheta(const py::object& T_) {
  require_numpy("SE2.to_xytheta");
  const Stack T = stack_of(T_, {3, 3}, "SE2.to_xytheta: T");
  auto out = make(T.lead, {3});
  for (py::ssize_t i = 0; i < T.n; ++i) {
    const SE2d g = Traits<SE2d>::from(T.item(i));
    double* o = out.mutable_data() + i * 3;
    o[0] = g.x(), o[1] = g.y(), o[2] = g.angle();
  }
  return out;
}

}  // namespace

void bind_lie(py::module_& m) {
  auto so2 = Ops<SO2d>::bind<SO2Tag>(
      m,
      "SO(2): planar rotations as (..., 2, 2) matrices; tangent = angle theta (rad), shape (...). "
      "Static functions only; right perturbations x (+) t = x Exp(t) (lie/lie.hpp).",
      "(...) (theta, rad)", "(..., 2)");
  auto se2 = Ops<SE2d>::bind<SE2Tag>(
      m,
      "SE(2): planar rigid motions as (..., 3, 3) homogeneous matrices; tangent [rho_x, rho_y, theta] "
      "(..., 3). Static functions only; right perturbations (lie/lie.hpp).",
      "(..., 3) [rho_x, rho_y, theta]", "(..., 2)");
  auto so3 = Ops<SO3d>::bind<SO3Tag>(
      m,
      "SO(3): rotations as (..., 3, 3) matrices (body -> world); tangent = rotation vector phi "
      "(..., 3) rad. Static functions only; right perturbations (lie/lie.hpp).",
      "(..., 3) (rotation vector, rad)", "(..., 3)");
  auto se3 = Ops<SE3d>::bind<SE3Tag>(
      m,
      "SE(3): rigid motions as (..., 4, 4) homogeneous matrices (T_w_b); tangent [rho(3), phi(3)] "
      "(..., 6), translation part first. Static functions only; right perturbations (lie/lie.hpp).",
      "(..., 6) [rho, phi]", "(..., 3)");
  so3.def_static("from_quaternion", &so3_from_quaternion, py::arg("q"), py::arg("order") = "wxyz",
                 "Rotation matrices (..., 3, 3) of quaternions (..., 4) in the given order ('wxyz' or 'xyzw'), "
                 "normalised; a non-finite or (near) zero quaternion raises ValueError.");
  so3.def_static("to_quaternion", &so3_to_quaternion, py::arg("R"), py::arg("order") = "wxyz",
                 "Unit quaternions (..., 4) with w >= 0 of rotation matrices (..., 3, 3), order 'wxyz' or 'xyzw'.");
  se3.def_static("from_rt", &se3_from_rt, py::arg("R"), py::arg("t"),
                 "Homogeneous matrices (..., 4, 4) from rotations (..., 3, 3) and translations (..., 3).");
  se2.def_static("from_xytheta", &se2_from_xytheta, py::arg("pose"),
                 "Homogeneous matrices (..., 3, 3) of planar poses (..., 3) [x, y, theta].");
  se2.def_static("to_xytheta", &se2_to_xytheta, py::arg("T"),
                 "Planar poses (..., 3) [x, y, theta], theta in [-pi, pi), of matrices (..., 3, 3).");
  so2.def_static("from_angle", [](const py::object& t) { return Ops<SO2d>::exp(t, false); }, py::arg("theta"),
                 "Rotation matrices (..., 2, 2) of angles theta (...) rad (SO2.exp).");
  so2.def_static("angle", [](const py::object& R) { return Ops<SO2d>::log(R, false); }, py::arg("R"),
                 "The angles theta in [-pi, pi) (shape (...)) of rotation matrices (..., 2, 2) (SO2.log).");
}

}  // namespace posefuse::python
