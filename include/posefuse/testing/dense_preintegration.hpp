#pragma once
/// @file
/// The straightforward dense form of posefuse's IMU pre-integration
/// (inertial/preintegration.hpp), as VINS-Mono propagates it: every sample
/// forms the full 15x15 transition F and the 15x18 noise Jacobian G and
/// computes \f$ J' = F J \f$ and \f$ P' = F P F^\top + G Q G^\top \f$
/// (Qin et al., VINS-Mono, IEEE T-RO 2018, eq 9-11; about 38 kflop a sample).
/// Same mathematics as the structured update — the same mid-point step,
/// the same F blocks (in the right, body form of the rotation error), the same noise model — so the
/// two agree to rounding (tests/inertial, 1e-12); it exists only as the
/// benchmark's and the tests' reference, not for estimation.

#include <Eigen/Core>
#include <posefuse/inertial/preintegration.hpp>

namespace posefuse::testing {

/// Blocks of one mid-point step's transition in the right (body) form of
/// inertial/preintegration.hpp's file comment.
struct MidpointStep {
  Eigen::Matrix3d E_T;     ///< \f$ \mathrm{Exp}(\bar\omega\delta t)^\top \f$
  Eigen::Matrix3d Jr_dt;   ///< \f$ J_r(\bar\omega\delta t)\,\delta t \f$
  Eigen::Matrix3d U_phi;   ///< \f$ \partial\bar u/\partial\delta\phi \f$
  Eigen::Matrix3d U_ba;    ///< \f$ \partial\bar u/\partial b_a \f$
  Eigen::Matrix3d U_bg;    ///< \f$ \partial\bar u/\partial b_g \f$
  Eigen::Matrix3d R0;      ///< \f$ \Delta R_k \f$
  Eigen::Matrix3d R1;      ///< \f$ \Delta R_{k+1} \f$
  Eigen::Matrix3d K;       ///< \f$ R_1[a'_{k+1}]_\times J_r\,\delta t \f$
};

/// Advances (p, R, v) by one mid-point step and returns the step's blocks.
inline MidpointStep midpoint_step(const ImuSample& s0, const ImuSample& s1, const ImuBias& bias,
                                  double dt, Eigen::Vector3d& p, SO3d& R, Eigen::Vector3d& v) {
  MidpointStep st;
  const Eigen::Vector3d w = 0.5 * (s0.gyro_radps + s1.gyro_radps) - bias.gyro;
  const Eigen::Vector3d a0 = s0.accel_mps2 - bias.accel;
  const Eigen::Vector3d a1 = s1.accel_mps2 - bias.accel;
  SO3d::Jacobian Jr;
  const SO3d E = SO3d::exp(Eigen::Vector3d(w * dt), &Jr);
  const SO3d R_next = R.compose(E);
  st.R0 = R.matrix();
  st.R1 = R_next.matrix();
  st.E_T = E.matrix().transpose();
  st.Jr_dt = Jr * dt;
  const Eigen::Vector3d u = 0.5 * (st.R0 * a0 + st.R1 * a1);
  const Eigen::Matrix3d R1_a1x = st.R1 * SO3d::hat(a1);
  st.U_phi = -0.5 * (st.R0 * SO3d::hat(a0) + R1_a1x * st.E_T);
  st.U_ba = -0.5 * (st.R0 + st.R1);
  st.K = R1_a1x * st.Jr_dt;
  st.U_bg = 0.5 * st.K;
  p += v * dt + (0.5 * dt * dt) * u;
  v += u * dt;
  R = R_next;
  return st;
}

/// Dense-matrix pre-integration (see the file comment); samples must be
/// given in order (no status checks: it is a reference, not an API).
class DensePreintegration {
 public:
  using Matrix15 = Eigen::Matrix<double, 15, 15>;

  DensePreintegration(const ImuNoise& noise, const ImuBias& bias) : noise_(noise), bias_(bias) {
    P_.setZero();
    F_prod_.setIdentity();
    Q_.setZero();
  }

  /// Integrates from the previous sample to `s` (the first sample only starts).
  void add(const ImuSample& s) {
    if (!started_) {
      last_ = s;
      started_ = true;
      return;
    }
    const double dt = seconds_between(s.t_ns, last_.t_ns);
    const MidpointStep st = midpoint_step(last_, s, bias_, dt, p_, R_, v_);
    const double h = 0.5 * dt * dt;
    Matrix15 F = Matrix15::Identity();  // order p, φ, v, b_a, b_g
    F.block<3, 3>(0, 3) = h * st.U_phi;
    F.block<3, 3>(0, 6) = dt * Eigen::Matrix3d::Identity();
    F.block<3, 3>(0, 9) = h * st.U_ba;
    F.block<3, 3>(0, 12) = h * st.U_bg;
    F.block<3, 3>(3, 3) = st.E_T;
    F.block<3, 3>(3, 12) = -st.Jr_dt;
    F.block<3, 3>(6, 3) = dt * st.U_phi;
    F.block<3, 3>(6, 9) = dt * st.U_ba;
    F.block<3, 3>(6, 12) = dt * st.U_bg;
    // Noise inputs n_a0, n_g0, n_a1, n_g1, n_ba, n_bg.
    Eigen::Matrix<double, 15, 18> G = Eigen::Matrix<double, 15, 18>::Zero();
    const Eigen::Matrix3d Ua0 = -0.5 * st.R0, Ua1 = -0.5 * st.R1, Ug = 0.25 * st.K;
    G.block<3, 3>(0, 0) = h * Ua0;
    G.block<3, 3>(6, 0) = dt * Ua0;
    G.block<3, 3>(0, 6) = h * Ua1;
    G.block<3, 3>(6, 6) = dt * Ua1;
    for (int c : {3, 9}) {
      G.block<3, 3>(0, c) = h * Ug;
      G.block<3, 3>(3, c) = -0.5 * st.Jr_dt;
      G.block<3, 3>(6, c) = dt * Ug;
    }
    G.block<3, 3>(9, 12).setIdentity();
    G.block<3, 3>(12, 15).setIdentity();
    const double ca = 2.0 * noise_.accel_noise_density * noise_.accel_noise_density / dt;
    const double cg = 2.0 * noise_.gyro_noise_density * noise_.gyro_noise_density / dt;
    Eigen::Matrix<double, 18, 1> q;
    q << Eigen::Vector3d::Constant(ca), Eigen::Vector3d::Constant(cg),
        Eigen::Vector3d::Constant(ca), Eigen::Vector3d::Constant(cg),
        Eigen::Vector3d::Constant(noise_.accel_random_walk * noise_.accel_random_walk * dt),
        Eigen::Vector3d::Constant(noise_.gyro_random_walk * noise_.gyro_random_walk * dt);
    Q_ = q.asDiagonal();
    F_prod_ = (F * F_prod_).eval();
    P_ = (F * P_ * F.transpose() + G * Q_ * G.transpose()).eval();
    last_ = s;
  }

  /// The covariance over [δp, δφ, δv, δb_a, δb_g].
  [[nodiscard]] const Matrix15& covariance() const { return P_; }
  /// ∂[Δp, Δφ, Δv]/∂[b_a, b_g]: the top-right block of the product of the F's.
  [[nodiscard]] Eigen::Matrix<double, 9, 6> bias_jacobian() const {
    return F_prod_.block<9, 6>(0, 9);
  }
  /// The pre-integrated measurement.
  [[nodiscard]] ImuDelta delta() const { return ImuDelta{p_, R_, v_}; }

 private:
  ImuNoise noise_;
  ImuBias bias_;
  bool started_ = false;
  ImuSample last_;
  Eigen::Vector3d p_ = Eigen::Vector3d::Zero(), v_ = Eigen::Vector3d::Zero();
  SO3d R_;
  Matrix15 P_, F_prod_;
  Eigen::Matrix<double, 18, 18> Q_;
};

}  // namespace posefuse::testing
