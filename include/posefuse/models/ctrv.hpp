#pragma once
/// @file
/// Constant turn rate and velocity (CTRV) on the plane, with white-noise
/// linear and yaw accelerations, and a position fix of its state.
///
/// State \f$ x = [p_x, p_y, \theta, v, \omega]^\top \f$ (m, m, rad, m/s,
/// rad/s): position, heading (counter-clockwise from the world x axis,
/// wrapped to [-pi, pi)), speed along the heading and yaw rate. Over
/// \f$ \Delta t \f$ (the difference of two timestamps) the vehicle follows
/// the circular arc of constant \f$ v, \omega \f$, written in chord form so
/// that it is smooth through \f$ \omega = 0 \f$ (no division by \f$ \omega \f$):
/// \f[ a = \omega\Delta t,\quad k = \mathrm{sinc}(a/2),\quad m = \theta + a/2 \f]
/// \f[ p_x' = p_x + v\Delta t\,k\cos m,\quad p_y' = p_y + v\Delta t\,k\sin m,\quad
///     \theta' = \mathrm{wrap}(\theta + a),\quad v' = v,\quad \omega' = \omega \f]
/// which equals the textbook \f$ p_x' = p_x + \tfrac{v}{\omega}(\sin(\theta + a)
/// - \sin\theta) \f$, \f$ p_y' = p_y + \tfrac{v}{\omega}(\cos\theta - \cos(\theta
/// + a)) \f$ for \f$ \omega \ne 0 \f$ and the straight line \f$ p' = p + v\Delta t
/// (\cos\theta, \sin\theta) \f$ at \f$ \omega = 0 \f$. sinc and its derivative
/// come from detail::sinc_and_derivative (models/unicycle.hpp): a series below
/// \f$ |a/2| < 0.125 \f$ (detail::kSincSeriesLimit), so the Jacobian is exact
/// and finite at every yaw rate, 0 included, and an ordinary step costs one
/// sine-cosine pair (of m). With \f$ s_m = \sin m,\ c_m = \cos m \f$ and
/// \f$ k' = \mathrm{sinc}'(a/2) \f$, the non-trivial Jacobian entries are
/// \f[ \partial p_x'/\partial(\theta, v, \omega) =
///     (-v\Delta t\,k s_m,\ \Delta t\,k c_m,\ \tfrac{v\Delta t^2}{2}(k' c_m - k s_m)) \f]
/// \f[ \partial p_y'/\partial(\theta, v, \omega) =
///     (v\Delta t\,k c_m,\ \Delta t\,k s_m,\ \tfrac{v\Delta t^2}{2}(k' s_m + k c_m)),
///     \quad \partial\theta'/\partial\omega = \Delta t \f]
/// (the rest is the identity).
///
/// **Process noise.** \f$ \dot v = w_a,\ \dot\omega = w_\omega \f$ with white
/// noise of spectral densities \f$ q_a \f$ (m²/s³) and \f$ q_\omega \f$
/// (rad²/s⁵). Q is the exact discretisation of that noise through the motion
/// linearised along the straight line of the mid-step heading \f$ m \f$: with
/// \f$ e = (\cos m, \sin m) \f$ (along track) and \f$ n = (-\sin m, \cos m) \f$
/// (across), the along-track position and speed form a double integrator and
/// the across-track position (gain v), heading and yaw rate a triple one:
/// \f[ Q = q_a \int_0^{\Delta t} g_a g_a^\top d\tau + q_\omega \int_0^{\Delta t}
///     g_\omega g_\omega^\top d\tau,\quad g_a = (\tau e, 0, 1, 0),
///     g_\omega = (\tfrac{v\tau^2}{2} n, \tau, 0, 1) \f]
/// i.e. \f$ Q_{pp} = q_a\tfrac{\Delta t^3}{3} e e^\top + q_\omega\tfrac{v^2\Delta
/// t^5}{20} n n^\top \f$, \f$ Q_{p\theta} = q_\omega\tfrac{v\Delta t^4}{8} n \f$,
/// \f$ Q_{pv} = q_a\tfrac{\Delta t^2}{2} e \f$, \f$ Q_{p\omega} =
/// q_\omega\tfrac{v\Delta t^3}{6} n \f$, \f$ Q_{\theta\theta} = q_\omega\tfrac{\Delta
/// t^3}{3} \f$, \f$ Q_{\theta\omega} = q_\omega\tfrac{\Delta t^2}{2} \f$,
/// \f$ Q_{vv} = q_a\Delta t \f$, \f$ Q_{\omega\omega} = q_\omega\Delta t \f$.
/// A sum of two Gram matrices, so PSD by construction; for \f$ \omega \ne 0 \f$ it
/// neglects the curvature of the arc within one step (the usual CTRV
/// approximation; Schubert, Richter & Wanielik, *Comparison and evaluation of
/// advanced motion models for vehicle tracking*, FUSION 2008).
///
/// ```cpp
/// posefuse::Ekf<posefuse::Ctrv<>, posefuse::CtrvPositionFix<>> ekf(
///     posefuse::Ctrv<>(/*q_accel=*/0.5, /*q_yaw_accel=*/0.1),
///     posefuse::CtrvPositionFix<>::isotropic(/*sigma=*/0.3));
/// ekf.reset(posefuse::CtrvState<>(x0, y0, heading0, 0.0, 0.0), P0);
/// (void)ekf.predict(posefuse::NoControl{}, t1 - t0);
/// (void)ekf.update<0>(Eigen::Vector2d(zx, zy));
/// ```

#include <Eigen/Core>
#include <array>
#include <cmath>
#include <concepts>
#include <posefuse/core/angles.hpp>
#include <posefuse/core/concepts.hpp>
#include <posefuse/core/error.hpp>
#include <posefuse/core/gaussian.hpp>
#include <posefuse/models/constant_velocity.hpp>
#include <posefuse/models/unicycle.hpp>

namespace posefuse {

/// CTRV state \f$ [p_x, p_y, \theta, v, \omega] \f$ (m, m, rad, m/s, rad/s) in
/// one fixed-size vector; a posefuse::State whose heading wraps: `plus` and
/// `minus` act on \f$ \mathbb{R}^2 \times S^1 \times \mathbb{R}^2 \f$.
template <std::floating_point T = double>
struct CtrvState {
  using Scalar = T;
  static constexpr int Dim = 5;
  using Vector = Eigen::Matrix<T, 5, 1>;
  using Tangent = Vector;
  static constexpr int kX = 0, kY = 1, kHeading = 2, kSpeed = 3, kYawRate = 4;

  Vector values = Vector::Zero();  ///< [x, y, heading, speed, yaw rate]

  CtrvState() = default;
  /// From the five numbers; the heading is wrapped to [-pi, pi).
  explicit CtrvState(const Vector& v) : values(v) { values(kHeading) = wrap_angle(v(kHeading)); }
  /// From position (m), heading (rad, wrapped), speed (m/s) and yaw rate (rad/s).
  CtrvState(T x, T y, T heading, T speed, T yaw_rate)
      : CtrvState(Vector(x, y, heading, speed, yaw_rate)) {}

  /// \f$ x \boxplus d \f$: vector addition, the heading wrapped.
  [[nodiscard]] CtrvState plus(const Tangent& d) const { return CtrvState(Vector(values + d)); }
  /// \f$ x \boxminus o \f$: vector difference, the heading difference wrapped.
  [[nodiscard]] Tangent minus(const CtrvState& o) const {
    Tangent d = values - o.values;
    d(kHeading) = angle_diff(values(kHeading), o.values(kHeading));
    return d;
  }

  [[nodiscard]] T x() const noexcept { return values(kX); }
  [[nodiscard]] T y() const noexcept { return values(kY); }
  [[nodiscard]] T heading() const noexcept { return values(kHeading); }
  [[nodiscard]] T speed() const noexcept { return values(kSpeed); }
  [[nodiscard]] T yaw_rate() const noexcept { return values(kYawRate); }
  /// The position as a vector (m).
  [[nodiscard]] Eigen::Matrix<T, 2, 1> position() const { return values.template head<2>(); }
  /// All five numbers (heading as stored, i.e. wrapped).
  [[nodiscard]] const Vector& vector() const noexcept { return values; }
};

/// Constant turn rate and velocity with white-noise accelerations; see the
/// file comment. A posefuse::MotionModel with posefuse::NoControl (the
/// motion is autonomous) and linearize() (HasLinearizePropagate).
template <std::floating_point T = double>
class Ctrv {
 public:
  using Scalar = T;
  using State = CtrvState<T>;
  using Control = NoControl;
  using Matrix = Eigen::Matrix<T, 5, 5>;

  /// @param[in] q_accel linear acceleration noise spectral density (m^2/s^3), > 0
  /// @param[in] q_yaw_accel yaw acceleration noise spectral density (rad^2/s^5), > 0
  /// @throws posefuse::invalid_argument unless both are finite and > 0
  Ctrv(T q_accel, T q_yaw_accel) : qa_(q_accel), qw_(q_yaw_accel) {
    if (!(q_accel > T(0)) || !std::isfinite(q_accel))
      throw invalid_argument("Ctrv: linear acceleration noise q_accel must be finite and > 0");
    if (!(q_yaw_accel > T(0)) || !std::isfinite(q_yaw_accel))
      throw invalid_argument("Ctrv: yaw acceleration noise q_yaw_accel must be finite and > 0");
  }

  /// predict(), jacobian() and noise() from one evaluation of the arc (the
  /// sine, cosine and sinc shared; see HasLinearize).
  struct Linearization {
    State state;      ///< \f$ f(x, \Delta t) \f$
    Matrix jacobian;  ///< \f$ J_{f,x} \f$
    Matrix noise;     ///< Q, as noise()
    /// \f$ J P J^\top \f$ from the seven non-trivial entries of J (J = I
    /// except \f$ J_{0,2..4} = a,\ J_{1,2..4} = b,\ J_{2,4} = dt \f$), in
    /// closed form: the columns \f$ c_j = P J_j^\top \f$ for j = 0, 1, 2 (the
    /// others are P's own), then row i of the result is \f$ J_i c_j \f$;
    /// one triangle is computed (42 multiply-adds instead of the 250 of two
    /// dense 5x5 products) and mirrored (see HasLinearizePropagate). P must
    /// be symmetric, as every covariance is.
    [[nodiscard]] Matrix propagate(const Matrix& P) const noexcept {
      const Matrix& J = jacobian;
      const T a2 = J(0, 2), a3 = J(0, 3), a4 = J(0, 4);
      const T b2 = J(1, 2), b3 = J(1, 3), b4 = J(1, 4);
      const T d = J(2, 4);
      using V5 = Eigen::Matrix<T, 5, 1>;
      using V4 = Eigen::Matrix<T, 4, 1>;
      using V3 = Eigen::Matrix<T, 3, 1>;
      // c_0 (all rows), c_1 (rows 1..4), c_2 (rows 2..4): what the lower triangle reads.
      const V5 c0 = P.col(0) + a2 * P.col(2) + a3 * P.col(3) + a4 * P.col(4);
      const V4 c1 = P.col(1).template tail<4>() + b2 * P.col(2).template tail<4>() +
                    b3 * P.col(3).template tail<4>() + b4 * P.col(4).template tail<4>();
      const V3 c2 = P.col(2).template tail<3>() + d * P.col(4).template tail<3>();
      Matrix out;
      out(0, 0) = c0(0) + a2 * c0(2) + a3 * c0(3) + a4 * c0(4);
      out(1, 0) = c0(1) + b2 * c0(2) + b3 * c0(3) + b4 * c0(4);
      out(2, 0) = c0(2) + d * c0(4);
      out(3, 0) = c0(3);
      out(4, 0) = c0(4);
      out(1, 1) = c1(0) + b2 * c1(1) + b3 * c1(2) + b4 * c1(3);
      out(2, 1) = c1(1) + d * c1(3);
      out(3, 1) = c1(2);
      out(4, 1) = c1(3);
      out(2, 2) = c2(0) + d * c2(2);
      out(3, 2) = c2(1);
      out(4, 2) = c2(2);
      out(3, 3) = P(3, 3);
      out(4, 3) = P(4, 3);
      out(4, 4) = P(4, 4);
      for (int j = 0; j < 5; ++j)
        for (int i = j + 1; i < 5; ++i) out(j, i) = out(i, j);
      return out;
    }
  };

  /// The step, its Jacobian and its noise at once.
  [[nodiscard]] Linearization linearize(const State& x, const Control&, T dt) const {
    Linearization out;
    const Arc arc(x, dt);
    out.state = arc.next(x);
    out.jacobian = arc.jacobian(x);
    out.noise = noise_of(arc, x.speed(), dt);
    return out;
  }
  /// \f$ f(x, \Delta t) \f$: the arc of constant speed and yaw rate.
  [[nodiscard]] State predict(const State& x, const Control&, T dt) const {
    return Arc(x, dt).next(x);
  }
  /// \f$ J_{f,x} \f$ (exact, finite at every yaw rate).
  [[nodiscard]] Matrix jacobian(const State& x, const Control&, T dt) const {
    return Arc(x, dt).jacobian(x);
  }
  /// The process noise Q over dt (file comment); zero at dt = 0.
  [[nodiscard]] Matrix noise(const State& x, const Control&, T dt) const {
    return noise_of(Arc(x, dt), x.speed(), dt);
  }

  [[nodiscard]] T q_accel() const noexcept { return qa_; }
  [[nodiscard]] T q_yaw_accel() const noexcept { return qw_; }

 private:
  /// The quantities the step, Jacobian and noise share.
  struct Arc {
    T dt, k, dk, c, s;
    Arc(const State& x, T dt_s) : dt(dt_s) {
      const T half = x.yaw_rate() * dt_s / T(2);
      detail::sinc_and_derivative(half, k, dk);
      const T m = x.heading() + half;
      c = std::cos(m);
      s = std::sin(m);
    }
    [[nodiscard]] State next(const State& x) const {
      const T ds = x.speed() * dt;
      typename State::Vector v = x.values;
      v(0) += ds * k * c;
      v(1) += ds * k * s;
      v(2) += x.yaw_rate() * dt;
      return State(v);  // wraps the heading
    }
    [[nodiscard]] Matrix jacobian(const State& x) const {
      const T v = x.speed();
      const T ds = v * dt;
      const T h = v * dt * dt / T(2);
      Matrix J = Matrix::Identity();
      J(0, 2) = -ds * k * s;
      J(0, 3) = dt * k * c;
      J(0, 4) = h * (dk * c - k * s);
      J(1, 2) = ds * k * c;
      J(1, 3) = dt * k * s;
      J(1, 4) = h * (dk * s + k * c);
      J(2, 4) = dt;
      return J;
    }
  };

  [[nodiscard]] Matrix noise_of(const Arc& arc, T v, T dt) const {
    const T d2 = dt * dt, d3 = d2 * dt;
    const T ex = arc.c, ey = arc.s;    // along track
    const T nx = -arc.s, ny = arc.c;   // across track
    const T pa = qa_ * d3 / T(3);                    // along-track position
    const T pn = qw_ * v * v * d3 * d2 / T(20);      // across-track position
    const T pt = qw_ * v * d2 * d2 / T(8);           // across position x heading
    const T pv = qa_ * d2 / T(2);                    // along position x speed
    const T pw = qw_ * v * d3 / T(6);                // across position x yaw rate
    Matrix Q = Matrix::Zero();
    Q(0, 0) = pa * ex * ex + pn * nx * nx;
    Q(1, 1) = pa * ey * ey + pn * ny * ny;
    Q(0, 1) = Q(1, 0) = pa * ex * ey + pn * nx * ny;
    Q(0, 2) = Q(2, 0) = pt * nx;
    Q(1, 2) = Q(2, 1) = pt * ny;
    Q(0, 3) = Q(3, 0) = pv * ex;
    Q(1, 3) = Q(3, 1) = pv * ey;
    Q(0, 4) = Q(4, 0) = pw * nx;
    Q(1, 4) = Q(4, 1) = pw * ny;
    Q(2, 2) = qw_ * d3 / T(3);
    Q(2, 4) = Q(4, 2) = qw_ * d2 / T(2);
    Q(3, 3) = qa_ * dt;
    Q(4, 4) = qw_ * dt;
    return Q;
  }

  T qa_;
  T qw_;
};

/// A planar position fix of a CTRV state, \f$ h(x) = (p_x, p_y) \f$,
/// \f$ H = [I_2\; 0] \f$, constant noise R (m²): seed 000's position
/// measurement on the CTRV state.
template <std::floating_point T = double>
class CtrvPositionFix {
 public:
  using State = CtrvState<T>;
  using Measurement = Eigen::Matrix<T, 2, 1>;
  using Noise = Eigen::Matrix<T, 2, 2>;
  static constexpr bool kTimeInvariant = true;             ///< H and R depend on neither x nor time
  static constexpr std::array<int, 2> kSelection = {0, 1};  ///< H selects x and y

  /// @param[in] R measurement noise (m^2)
  /// @throws posefuse::invalid_argument unless R is symmetric positive definite
  explicit CtrvPositionFix(const Noise& R) : R_(R) {
    if (!is_positive_definite(R_))
      throw invalid_argument("CtrvPositionFix: measurement noise R must be symmetric positive definite");
  }
  /// Isotropic noise with standard deviation sigma (m) on both axes.
  static CtrvPositionFix isotropic(T sigma) { return CtrvPositionFix(Noise::Identity() * sigma * sigma); }

  [[nodiscard]] Measurement predict(const State& x) const { return x.position(); }
  [[nodiscard]] Eigen::Matrix<T, 2, 5> jacobian(const State&) const {
    Eigen::Matrix<T, 2, 5> H = Eigen::Matrix<T, 2, 5>::Zero();
    H(0, 0) = H(1, 1) = T(1);
    return H;
  }
  [[nodiscard]] const Noise& noise() const noexcept { return R_; }

 private:
  Noise R_;
};

static_assert(MotionModel<Ctrv<double>> && HasLinearizePropagate<Ctrv<double>>);
static_assert(MeasurementModel<CtrvPositionFix<double>>);

}  // namespace posefuse
