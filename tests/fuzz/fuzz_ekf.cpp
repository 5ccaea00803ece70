// libFuzzer harness: the contract of posefuse::Ekf (filters/ekf.hpp).
//
// Input: a model choice, the models' parameters, then up to kMaxSteps
// operations, all decoded by posefuse_fuzz::ByteReader (numbers include
// NaN, Inf, DBL_MAX, denormals and negatives):
//   reset(x0, P0)               P0 diagonal, L L^T, symmetric or arbitrary
//   predict(u, dt)
//   update<I>(z)                held model I, compared with update_with on a copy
//   update<I>(z, gate)          NIS number, or a functor bool(r, S[, nis])
//   update_with(H(noise), z[, gate])   a model built from decoded noise
//   set_gate<I>(threshold)
// over four filters: constant velocity + 1/2/4-D position fixes (the 1x1,
// 2x2 closed-form and 4x4 Cholesky solves), unicycle and SE(2) odometry +
// planar pose fix + heading fix (wrapped states and measurements), and the
// planar displacement model + 2-D position fix (identity Jacobians).
//
// Properties checked after every operation:
//  * a status other than kApplied leaves state, covariance and last Jacobian
//    bit-identical (memcmp) and the filter as initialised as before;
//  * after kApplied the state is finite and P is finite, symmetric and PSD
//    (posefuse::is_positive_semidefinite);
//  * the statuses the header documents for a given input (kNotInitialised
//    before reset, kNonFinite for a non-finite dt, kInvalidInput for dt < 0,
//    kGated when a gate functor says no, NIS <= a numeric gate when applied);
//  * reset() throws posefuse::invalid_argument exactly when x0 is not finite
//    or P0 is not a finite symmetric PSD matrix, and then changes nothing;
//    set_gate() throws exactly for a threshold that is not > 0;
//  * update<I>(z) (which may reuse a memoised gain) gives the same status,
//    state and covariance as update_with(sensor<I>(), z, gate<I>()).
// Any other exception, crash or sanitizer report is a finding too.
// Set POSEFUSE_FUZZ_TRACE=1 to print every operation with its values (to
// turn a crash input into a Catch2 reproducer), and
// POSEFUSE_FUZZ_EKF_SKIP_SOUNDNESS=1 to skip the finite/symmetric/PSD check
// after kApplied while a known finding of that kind awaits its fix.

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <iomanip>
#include <limits>
#include <optional>
#include <sstream>
#include <string>
#include <type_traits>
#include <utility>

#include <posefuse/core/error.hpp>
#include <posefuse/core/gaussian.hpp>
#include <posefuse/core/status.hpp>
#include <posefuse/filters/ekf.hpp>
#include <posefuse/lie/se2.hpp>
#include <posefuse/lie/so2.hpp>
#include <posefuse/models/constant_velocity.hpp>
#include <posefuse/models/heading_fix.hpp>
#include <posefuse/models/planar_displacement.hpp>
#include <posefuse/models/planar_pose.hpp>
#include <posefuse/models/planar_pose_fix.hpp>
#include <posefuse/models/position.hpp>
#include <posefuse/models/se2_odometry.hpp>
#include <posefuse/models/unicycle.hpp>

#include "fuzz_support.hpp"

namespace {

using posefuse::FilterStatus;
using posefuse_fuzz::ByteReader;
using posefuse_fuzz::require;

constexpr int kMaxSteps = 64;

const bool g_trace = std::getenv("POSEFUSE_FUZZ_TRACE") != nullptr;
/// POSEFUSE_FUZZ_EKF_SKIP_SOUNDNESS=1 skips the finite/symmetric/PSD check
/// after kApplied (every other check stays), to look past a known finding of
/// that kind while its fix is pending. CI never sets it.
const bool g_skip_soundness = std::getenv("POSEFUSE_FUZZ_EKF_SKIP_SOUNDNESS") != nullptr;

// --- values: decoding, bitwise and value comparison, printing --------------

template <class T>
struct Tag {};

template <int N>
Eigen::Matrix<double, N, 1> decode(ByteReader& in, Tag<Eigen::Matrix<double, N, 1>>) {
  Eigen::Matrix<double, N, 1> v;
  for (int i = 0; i < N; ++i) v(i) = in.real();
  return v;
}
posefuse::PlanarPose<double> decode(ByteReader& in, Tag<posefuse::PlanarPose<double>>) {
  posefuse::PlanarPose<double> p;
  p.x = in.real();
  p.y = in.real();
  p.theta = in.real();
  return p;
}
posefuse::SO2<double> decode(ByteReader& in, Tag<posefuse::SO2<double>>) {
  return posefuse::SO2<double>(in.real());
}
posefuse::SE2<double> decode(ByteReader& in, Tag<posefuse::SE2<double>>) {
  const double x = in.real();
  const double y = in.real();
  const double theta = in.real();
  return posefuse::SE2<double>(x, y, theta);
}
posefuse::NoControl decode(ByteReader&, Tag<posefuse::NoControl>) { return {}; }

template <class T>
T decode_as(ByteReader& in) {
  return decode(in, Tag<T>{});
}

/// A covariance-shaped matrix: diagonal, L L^T, symmetric or arbitrary.
template <int N>
Eigen::Matrix<double, N, N> decode_cov(ByteReader& in) {
  using M = Eigen::Matrix<double, N, N>;
  M P = M::Zero();
  switch (in.choice(4)) {
    case 0:
      for (int i = 0; i < N; ++i) P(i, i) = in.real();
      break;
    case 1: {
      M L = M::Zero();
      for (int i = 0; i < N; ++i)
        for (int j = 0; j <= i; ++j) L(i, j) = in.real();
      P = L * L.transpose();
      break;
    }
    case 2:
      for (int i = 0; i < N; ++i)
        for (int j = i; j < N; ++j) P(i, j) = P(j, i) = in.real();
      break;
    default:
      for (int i = 0; i < N; ++i)
        for (int j = 0; j < N; ++j) P(i, j) = in.real();
      break;
  }
  return P;
}

template <class Derived>
bool same_bits(const Eigen::PlainObjectBase<Derived>& a, const Eigen::PlainObjectBase<Derived>& b) {
  return std::memcmp(a.data(), b.data(), sizeof(typename Derived::Scalar) * std::size_t(a.size())) == 0;
}
bool same_bits(const posefuse::PlanarPose<double>& a, const posefuse::PlanarPose<double>& b) {
  const double u[3] = {a.x, a.y, a.theta};
  const double v[3] = {b.x, b.y, b.theta};
  return std::memcmp(u, v, sizeof u) == 0;
}

template <class Derived>
bool same_value(const Eigen::PlainObjectBase<Derived>& a, const Eigen::PlainObjectBase<Derived>& b) {
  return a == b;
}
bool same_value(const posefuse::PlanarPose<double>& a, const posefuse::PlanarPose<double>& b) {
  return a.x == b.x && a.y == b.y && a.theta == b.theta;
}

template <class Derived>
bool finite(const Eigen::PlainObjectBase<Derived>& a) {
  return a.allFinite();
}
bool finite(const posefuse::PlanarPose<double>& p) {
  return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.theta);
}

std::string show(double v) {
  std::ostringstream s;
  s << std::setprecision(17) << v;
  return s.str();
}
template <class Derived>
std::string show(const Eigen::PlainObjectBase<Derived>& m) {
  std::ostringstream s;
  s << std::setprecision(17) << "[";
  for (Eigen::Index i = 0; i < m.rows(); ++i) {
    s << (i ? "; " : "");
    for (Eigen::Index j = 0; j < m.cols(); ++j) s << (j ? ", " : "") << m(i, j);
  }
  s << "]";
  return s.str();
}
std::string show(const posefuse::PlanarPose<double>& p) {
  return "{x " + show(p.x) + ", y " + show(p.y) + ", theta " + show(p.theta) + "}";
}
std::string show(const posefuse::SO2<double>& r) { return "SO2(angle " + show(r.angle()) + ")"; }
std::string show(const posefuse::SE2<double>& g) {
  return "SE2(" + show(g.x()) + ", " + show(g.y()) + ", " + show(g.angle()) + ")";
}
std::string show(const posefuse::NoControl&) { return "{}"; }

/// Prints the line `make_line()` returns when POSEFUSE_FUZZ_TRACE is set
/// (the callable keeps untraced runs from formatting anything).
template <class MakeLine>
void trace(const MakeLine& make_line) {
  if (g_trace) std::fprintf(stderr, "  %s\n", std::string(make_line()).c_str());
}

// --- the filter before and after a step ------------------------------------

template <class Filter>
struct Snapshot {
  typename Filter::StateType x;
  typename Filter::Covariance P;
  typename Filter::Covariance F;
  bool initialised;
  explicit Snapshot(const Filter& f)
      : x(f.state()), P(f.covariance()), F(f.last_jacobian()), initialised(f.initialised()) {}
};

// `what` (a callable returning std::string) names the step in a finding;
// it is only called when a check fails.

template <class Filter, class What>
void require_unchanged(const Snapshot<Filter>& s, const Filter& f, const What& what) {
  require(same_bits(s.x, f.state()) && same_bits(s.P, f.covariance()) &&
              same_bits(s.F, f.last_jacobian()) && s.initialised == f.initialised(),
          [&] {
            return what() + " but changed the filter: x " + show(s.x) + " -> " + show(f.state()) +
                   ", P " + show(s.P) + " -> " + show(f.covariance()) + ", last_jacobian() " +
                   show(s.F) + " -> " + show(f.last_jacobian()) + ", initialised " +
                   std::to_string(s.initialised) + " -> " + std::to_string(f.initialised());
          });
}

template <class Filter, class What>
void require_sound(const Snapshot<Filter>& s, const Filter& f, const What& what) {
  const auto& P = f.covariance();
  const auto before = [&] { return " (before: x " + show(s.x) + ", P " + show(s.P) + ")"; };
  require(finite(f.state()),
          [&] { return what() + " left a non-finite state " + show(f.state()) + before(); });
  require(P.allFinite(),
          [&] { return what() + " left a non-finite covariance " + show(P) + before(); });
  require(posefuse::is_symmetric(P),
          [&] { return what() + " left a non-symmetric covariance " + show(P) + before(); });
  if (posefuse::is_positive_semidefinite(P)) return;
  // Tell an indefinite P from a criterion that refuses a PSD one: the
  // smallest eigenvalue of the scale-free form D^-1/2 P D^-1/2 (the form the
  // library's pivots are tested on), against the same 16 n eps allowance.
  constexpr int n = Filter::Dim;
  Eigen::Matrix<double, n, 1> inv_scale;
  for (int i = 0; i < n; ++i) inv_scale(i) = P(i, i) > 0 ? 1.0 / std::sqrt(P(i, i)) : 1.0;
  const typename Filter::Covariance C = inv_scale.asDiagonal() * P * inv_scale.asDiagonal();
  const double lambda_min =
      Eigen::SelfAdjointEigenSolver<typename Filter::Covariance>(C, Eigen::EigenvaluesOnly)
          .eigenvalues()
          .minCoeff();
  const bool psd = (P.diagonal().array() >= 0).all() &&
                   lambda_min >= -16.0 * n * std::numeric_limits<double>::epsilon();
  posefuse_fuzz::finding(
      (psd ? "posefuse::is_positive_semidefinite refuses the PSD covariance that " + what() +
                 " left (smallest eigenvalue of its scale-free form " + show(lambda_min) + "): "
           : what() + " left an indefinite covariance (smallest eigenvalue of its scale-free form " +
                 show(lambda_min) + "): ") +
      show(P) + before());
}

/// The check every step ends with.
template <class Filter, class What>
void require_contract(const Snapshot<Filter>& s, const Filter& f, FilterStatus st,
                      const What& what) {
  const auto w = [&] { return what() + " returned " + posefuse::to_string(st); };
  trace([&] { return "-> " + std::string(posefuse::to_string(st)); });
  if (!s.initialised) require(st == FilterStatus::kNotInitialised, [&] { return w() + " before reset()"; });
  if (st == FilterStatus::kApplied) {
    if (!g_skip_soundness) require_sound(s, f, w);
  } else {
    require_unchanged(s, f, w);
  }
}

template <std::size_t N, class F>
void with_index(std::size_t i, F&& f) {
  [&]<std::size_t... I>(std::index_sequence<I...>) {
    ((i == I ? (f.template operator()<I>(), 0) : 0), ...);
  }(std::make_index_sequence<N>{});
}

// --- the four filters ------------------------------------------------------

struct ConstantVelocitySetup {
  static constexpr const char* kName = "ConstantVelocity2 + PositionFix<4,1|2|4>";
  using Filter = posefuse::Ekf<posefuse::ConstantVelocity2<double>, posefuse::PositionFix<4, 1>,
                               posefuse::PositionFix<4, 2>, posefuse::PositionFix<4, 4>>;
  static constexpr std::size_t kSensors = 3;
  static Filter make(ByteReader& in) {
    const double q = in.real();
    const auto R1 = decode_cov<1>(in);
    const auto R2 = decode_cov<2>(in);
    const auto R4 = decode_cov<4>(in);
    trace([&] { return "ConstantVelocity2(q " + show(q) + "), PositionFix R " + show(R1) + ", " + show(R2) + ", " +
          show(R4); });
    return Filter(posefuse::ConstantVelocity2<double>(q), posefuse::PositionFix<4, 1>(R1),
                  posefuse::PositionFix<4, 2>(R2), posefuse::PositionFix<4, 4>(R4));
  }
  template <class F>
  static void with_adhoc_sensor(ByteReader& in, F&& f) {
    switch (in.choice(3)) {
      case 0: {
        const auto R = decode_cov<1>(in);
        trace([&] { return "ad-hoc PositionFix<4,1>(R " + show(R) + ")"; });
        f(posefuse::PositionFix<4, 1>(R));
        break;
      }
      case 1: {
        const auto R = decode_cov<2>(in);
        trace([&] { return "ad-hoc PositionFix<4,2>(R " + show(R) + ")"; });
        f(posefuse::PositionFix<4, 2>(R));
        break;
      }
      default: {
        const auto R = decode_cov<4>(in);
        trace([&] { return "ad-hoc PositionFix<4,4>(R " + show(R) + ")"; });
        f(posefuse::PositionFix<4, 4>(R));
        break;
      }
    }
  }
};

/// Pose fixes for the planar-pose filters.
struct PlanarSensors {
  template <class F>
  static void with_adhoc_sensor(ByteReader& in, F&& f) {
    if (in.choice(2) == 0) {
      const auto R = decode_cov<3>(in);
      trace([&] { return "ad-hoc PlanarPoseFix(R " + show(R) + ")"; });
      f(posefuse::PlanarPoseFix<double>(R));
    } else {
      const double sigma = in.real();
      trace([&] { return "ad-hoc HeadingFix(sigma " + show(sigma) + ")"; });
      f(posefuse::HeadingFix<double>(sigma));
    }
  }
};

struct UnicycleSetup : PlanarSensors {
  static constexpr const char* kName = "Unicycle + PlanarPoseFix + HeadingFix";
  using Filter =
      posefuse::Ekf<posefuse::Unicycle<double>, posefuse::PlanarPoseFix<double>, posefuse::HeadingFix<double>>;
  static constexpr std::size_t kSensors = 2;
  static Filter make(ByteReader& in) {
    posefuse::Unicycle<double> m;
    m.method = in.choice(2) == 0 ? posefuse::Integration::kEuler : posefuse::Integration::kExactArc;
    m.control_cov = decode_cov<2>(in);
    // Unicycle is an aggregate that does not validate control_cov; an
    // indefinite one is a misconfiguration no filter can detect.
    if (!posefuse::is_positive_semidefinite(m.control_cov))
      throw posefuse::invalid_argument("fuzz: Unicycle::control_cov must be PSD");
    const auto R = decode_cov<3>(in);
    const double sigma = in.real();
    trace([&] { return std::string("Unicycle(") + (m.method == posefuse::Integration::kEuler ? "Euler" : "ExactArc") +
          ", control_cov " + show(m.control_cov) + "), PlanarPoseFix(R " + show(R) +
          "), HeadingFix(sigma " + show(sigma) + ")"; });
    return Filter(m, posefuse::PlanarPoseFix<double>(R), posefuse::HeadingFix<double>(sigma));
  }
};

struct Se2OdometrySetup : PlanarSensors {
  static constexpr const char* kName = "Se2Odometry + PlanarPoseFix + HeadingFix";
  using Filter = posefuse::Ekf<posefuse::Se2Odometry<double>, posefuse::PlanarPoseFix<double>,
                               posefuse::HeadingFix<double>>;
  static constexpr std::size_t kSensors = 2;
  static Filter make(ByteReader& in) {
    posefuse::Se2OdometryNoise<double> n;
    n.xy_sigma_per_sqrt_m = in.real();
    n.theta_sigma_per_sqrt_m = in.real();
    n.theta_sigma_per_sqrt_rad = in.real();
    const auto R = decode_cov<3>(in);
    const double sigma = in.real();
    trace([&] { return "Se2Odometry(" + show(n.xy_sigma_per_sqrt_m) + ", " + show(n.theta_sigma_per_sqrt_m) + ", " +
          show(n.theta_sigma_per_sqrt_rad) + "), PlanarPoseFix(R " + show(R) + "), HeadingFix(sigma " +
          show(sigma) + ")"; });
    return Filter(posefuse::Se2Odometry<double>(n), posefuse::PlanarPoseFix<double>(R),
                  posefuse::HeadingFix<double>(sigma));
  }
};

struct DisplacementSetup {
  static constexpr const char* kName = "PlanarDisplacement + PositionFix<2,2>";
  using Filter = posefuse::Ekf<posefuse::PlanarDisplacement<double>, posefuse::PositionFix<2, 2>>;
  static constexpr std::size_t kSensors = 1;
  static Filter make(ByteReader& in) {
    const auto Rp = decode_cov<2>(in);
    const auto Rm = decode_cov<2>(in);
    trace([&] { return "PlanarDisplacement(R " + show(Rp) + "), PositionFix<2,2>(Q " + show(Rm) + ")"; });
    return Filter(posefuse::PlanarDisplacement<double>(Rp), posefuse::PositionFix<2, 2>(Rm));
  }
  template <class F>
  static void with_adhoc_sensor(ByteReader& in, F&& f) {
    const auto R = decode_cov<2>(in);
    trace([&] { return "ad-hoc PositionFix<2,2>(Q " + show(R) + ")"; });
    f(posefuse::PositionFix<2, 2>(R));
  }
};

// --- the operations --------------------------------------------------------

template <class Setup>
void run(ByteReader& in) {
  using Filter = typename Setup::Filter;
  using State = typename Filter::StateType;
  using Control = typename Filter::Control;
  trace([&] { return Setup::kName; });
  std::optional<Filter> made;
  try {
    made.emplace(Setup::make(in));
  } catch (const posefuse::invalid_argument& e) {
    trace([&] { return std::string("model rejected: ") + e.what(); });
    return;
  }
  Filter& ekf = *made;
  for (int step = 0; step < kMaxSteps && !in.empty(); ++step) {
    const Snapshot<Filter> before(ekf);
    switch (in.choice(6)) {
      case 0: {  // reset
        const State x0 = decode_as<State>(in);
        const typename Filter::Covariance P0 = decode_cov<Filter::Dim>(in);
        trace([&] { return "reset(x0 " + show(x0) + ", P0 " + show(P0) + ")"; });
        const bool valid = finite(x0) && posefuse::is_positive_semidefinite(P0);
        bool threw = false;
        try {
          ekf.reset(x0, P0);
        } catch (const posefuse::invalid_argument& e) {
          threw = true;
          trace([&] { return std::string("-> invalid_argument: ") + e.what(); });
        }
        if (threw) {
          require(!valid, [&] {
            return "reset rejected a finite state and a finite symmetric PSD covariance " + show(P0);
          });
          require_unchanged(before, ekf, [] { return std::string("reset threw invalid_argument"); });
        } else {
          require(valid, [&] {
            return "reset accepted x0 " + show(x0) + ", P0 " + show(P0) +
                   " (not finite, or not a finite symmetric PSD covariance)";
          });
          require(same_bits(ekf.state(), x0) && same_bits(ekf.covariance(), P0) && ekf.initialised(),
                  "reset did not set the belief it was given");
        }
        break;
      }
      case 1: {  // predict
        const Control u = decode_as<Control>(in);
        const double dt = in.real();
        trace([&] { return "predict(u " + show(u) + ", dt " + show(dt) + ")"; });
        const FilterStatus st = ekf.predict(u, dt);
        if (before.initialised && !std::isfinite(dt))
          require(st == FilterStatus::kNonFinite, "predict with a non-finite dt must return kNonFinite");
        if (before.initialised && std::isfinite(dt) && dt < 0)
          require(st == FilterStatus::kInvalidInput, "predict with dt < 0 must return kInvalidInput");
        require_contract(before, ekf, st,
                         [&] { return "predict(u " + show(u) + ", dt " + show(dt) + ")"; });
        break;
      }
      case 2: {  // held model, compared with update_with on a copy
        with_index<Setup::kSensors>(in.choice(Setup::kSensors), [&]<std::size_t I>() {
          using Z = typename Filter::template SensorType<I>::Measurement;
          const Z z = decode_as<Z>(in);
          trace([&] { return "update<" + std::to_string(I) + ">(z " + show(z) + ")"; });
          Filter twin = ekf;
          const auto r = ekf.template update<I>(z);
          const auto r2 = twin.update_with(twin.template sensor<I>(), z, twin.template gate<I>());
          const auto what = [&] { return "update<" + std::to_string(I) + ">(z " + show(z) + ")"; };
          require(r.status == r2.status && same_value(ekf.state(), twin.state()) &&
                      ekf.covariance() == twin.covariance(),
                  [&] {
                    return what() + " (" + posefuse::to_string(r.status) +
                           ") and update_with(sensor<I>()) (" + posefuse::to_string(r2.status) +
                           ") disagree: P " + show(ekf.covariance()) + " vs " + show(twin.covariance());
                  });
          require_contract(before, ekf, r.status, what);
        });
        break;
      }
      case 3: {  // held model with a per-call gate
        with_index<Setup::kSensors>(in.choice(Setup::kSensors), [&]<std::size_t I>() {
          using Z = typename Filter::template SensorType<I>::Measurement;
          const Z z = decode_as<Z>(in);
          const std::size_t mode = in.choice(3);
          const auto what = [&] { return "update<" + std::to_string(I) + ">(z " + show(z) + ", gate)"; };
          if (mode == 0) {
            const double g = in.real();
            trace([&] { return what() + " with NIS gate " + show(g); });
            const auto r = ekf.template update<I>(z, g);
            if (r.status == FilterStatus::kApplied)
              require(r.nis <= g, [&] {
                return what() + ": applied although NIS " + show(r.nis) + " > gate " + show(g);
              });
            require_contract(before, ekf, r.status, what);
          } else {
            const bool accept = in.choice(2) == 0;
            bool called = false;
            trace([&] { return what() + " with a functor returning " + (accept ? "true" : "false"); });
            FilterStatus st;
            if (mode == 1) {
              const auto gate = [&](const auto&, const auto&) {
                called = true;
                return accept;
              };
              st = ekf.template update<I>(z, gate).status;
            } else {
              const auto gate = [&](const auto&, const auto&, double) {
                called = true;
                return accept;
              };
              st = ekf.template update<I>(z, gate).status;
            }
            if (called && !accept)
              require(st == FilterStatus::kGated, [&] {
                return what() + ": the gate said no but the status is " + posefuse::to_string(st);
              });
            require_contract(before, ekf, st, what);
          }
        });
        break;
      }
      case 4: {  // a model built for this one measurement
        try {
          Setup::with_adhoc_sensor(in, [&](const auto& sensor) {
            using H = std::decay_t<decltype(sensor)>;
            const typename H::Measurement z = decode_as<typename H::Measurement>(in);
            const bool gated = in.choice(2) == 0;
            const double g = gated ? in.real() : std::numeric_limits<double>::infinity();
            trace([&] { return "update_with(z " + show(z) + ", gate " + show(g) + ")"; });
            const auto r = ekf.update_with(sensor, z, g);
            if (r.status == FilterStatus::kApplied)
              require(r.nis <= g, [&] {
                return "update_with: applied although NIS " + show(r.nis) + " > gate " + show(g);
              });
            require_contract(before, ekf, r.status, [&] { return "update_with(z " + show(z) + ")"; });
          });
        } catch (const posefuse::invalid_argument& e) {
          trace([&] { return std::string("-> model rejected: ") + e.what(); });
          require_unchanged(before, ekf,
                            [] { return std::string("building a measurement model threw"); });
        }
        break;
      }
      default: {  // set_gate
        with_index<Setup::kSensors>(in.choice(Setup::kSensors), [&]<std::size_t I>() {
          const double g = in.real();
          trace([&] { return "set_gate<" + std::to_string(I) + ">(" + show(g) + ")"; });
          bool threw = false;
          try {
            ekf.template set_gate<I>(g);
          } catch (const posefuse::invalid_argument&) {
            threw = true;
          }
          require(threw == !(g > 0),
                  [&] { return "set_gate(" + show(g) + ") must throw exactly when not > 0"; });
          if (!threw) require(ekf.template gate<I>() == g, "set_gate did not set the gate");
          require_unchanged(before, ekf, [] { return std::string("set_gate"); });
        });
        break;
      }
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  ByteReader in(data, size);
  switch (in.choice(4)) {
    case 0: run<ConstantVelocitySetup>(in); break;
    case 1: run<UnicycleSetup>(in); break;
    case 2: run<Se2OdometrySetup>(in); break;
    default: run<DisplacementSetup>(in); break;
  }
  return 0;
}
