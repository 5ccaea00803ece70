#pragma once
/// @file
/// The nonlinear least-squares problem of a visual-inertial window
/// (vio/window_state.hpp) and its Levenberg–Marquardt solve:
/// \f[ F(x) = |r_{prior}(x)|^2 + \sum_k |L_k^{-1} r_{imu,k}(x)|^2
///          + \sum_{l, j} \rho\big(|r_{l j}(x)|^2\big), \f]
/// marginalisation prior, IMU factors (inertial/imu_factor.hpp) and robust
/// reprojection residuals (vio/reprojection_factor.hpp, vio/robust_loss.hpp).
///
/// **Normal equations with the landmarks eliminated.** Each feature has one
/// variable, its inverse depth λ, so its block of the Hessian is a scalar
/// \f$ h_l \f$ and its coupling to the camera-side variables is one 6-vector
/// \f$ w_{l,f} = \sum J_f^\top J_\lambda \f$ per keyframe pose it touches (and one for
/// the extrinsic). The Schur complement
/// \f[ H_s = H_{cc} - \sum_l \sum_{f, g} w_{l,f} w_{l,g}^\top / h_l, \qquad
///     b_s = b_c - \sum_l w_{l,f}\, b_l / h_l \f]
/// is formed with fixed-size 6x6 products and each λ is back-substituted:
/// \f$ \delta\lambda_l = -(b_l + \sum_f w_{l,f}^\top \delta_f) / h_l \f$.
///
/// **The reduced system's profile.** The reduced system has 15 unknowns per
/// keyframe (+ 6 for the extrinsic) and is sparse by blocks: the IMU factors
/// couple consecutive keyframes, a feature couples the keyframes that see it
/// (after the elimination, all of them pairwise), the prior couples the
/// keyframes it holds, and the extrinsic, when estimated, couples everything.
/// linearize() records for each keyframe the oldest keyframe it is coupled
/// to (its block row's profile); the damped system is then assembled on that
/// lower profile only and factored by a block Cholesky on 15x15 blocks that
/// keeps the profile (vio/detail/block_profile_cholesky.hpp; the extrinsic
/// is a dense border): for keyframes whose features span a few keyframes,
/// the work grows linearly with the window instead of cubically. When the
/// profile would save less than 30 % of the work of a dense factorisation
/// (features tracked across most of the window), the lower triangle is
/// factored densely (LLT). If a Cholesky finds the
/// damped system not positive definite, it is solved by a dense LDLT (which
/// also accepts a semi-definite system) and the step is rejected only when
/// that fails too or gives a non-finite step.
///
/// **Levenberg–Marquardt.** \f$ \mu\,\mathrm{diag}(H) \f$ (each entry clamped to
/// [1e-6, 1e32], as Ceres does) is added to the Hessian, λ's included, before the elimination. A trial
/// step is accepted when the cost decreases (μ /= 3), else rejected (μ *= 4).
/// A rejected trial restores the variables it changed (no copy of the window);
/// the prior's constant \f$ J^\top J \f$ and \f$ J^\top r_0 \f$ are formed once per solve.
/// The solve stops after `max_iterations` trials — an iteration cap, never a
/// clock, so a run gives bit-identical results on any computer — or earlier
/// when a step changes the cost by less than `function_tolerance` relatively.
///
/// **First-estimate Jacobians.** With `first_estimate_jacobians`, every
/// factor's Jacobian with respect to a keyframe (or the extrinsic) that is in
/// the prior is evaluated at its first estimate (VioFrame::fej) while the
/// residual is evaluated at the current estimate (Huang, Mourikis,
/// Roumeliotis 2009; Dong-Si and Mourikis 2011 for sliding windows). All
/// factors then see one linearisation point per variable, so the four
/// unobservable directions (global translation, yaw about gravity) stay in
/// the null space of the Hessian; the prior's Jacobian is constant.
///
/// **Re-propagation.** Before each linearisation, a pre-integration whose
/// linearisation bias is farther than its PreintegrationOptions thresholds
/// from the current bias estimate of its first keyframe is re-integrated
/// (Preintegration::update_bias) and its IMU factor rebuilt.
///
/// **Zero velocity.** A keyframe marked `stationary` (the image shows no
/// motion, vio/estimator.hpp) has the residual \f$ v / \sigma_0 \f$ with
/// \f$ \sigma_0 \f$ = `stationary_velocity_sigma_mps`: at rest the features
/// cannot be triangulated, and without it the IMU alone would let the
/// velocity, hence the position, drift.
///
/// Observations whose point lies closer than `min_depth` in front of the
/// observing camera, and features with λ <= 0, contribute nothing (the same
/// rule in the cost and in the linearisation).

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <vector>

#include <posefuse/vio/detail/block_profile_cholesky.hpp>
#include <posefuse/vio/robust_loss.hpp>
#include <posefuse/vio/window_state.hpp>

namespace posefuse {

/// Options of the window solve.
struct WindowSolveOptions {
  int max_iterations = 10;                 ///< cap on LM trials (each one linear solve)
  double initial_damping = 1e-4;           ///< initial μ
  double function_tolerance = 1e-10;       ///< stop when |ΔF| / F falls below this
  /// On residuals in units of σ; the scale √2 is one standard deviation of a
  /// residual that carries the anchor's and the observer's pixel noise.
  ReprojectionLoss loss{ReprojectionLoss::Kind::kCauchy, 1.4142135623730951};
  bool first_estimate_jacobians = true;    ///< see the file comment
  double min_depth = 0.05;                 ///< observations closer than this (m) are ignored
  double stationary_velocity_sigma_mps = 0.01;  ///< σ of the zero-velocity factor of a stationary keyframe
};

/// What a solve did.
struct WindowSolveSummary {
  int iterations = 0;         ///< LM trials
  int accepted = 0;           ///< accepted steps
  int repropagated = 0;       ///< pre-integrations re-integrated
  double initial_cost = 0.0;  ///< F before
  double final_cost = 0.0;    ///< F after
};

/// Which factors WindowProblem::linearize takes (all of them for a solve;
/// subsets for marginalisation).
struct WindowSelection {
  bool prior = true;                                      ///< the marginalisation prior
  std::vector<char> imu;                                  ///< per slot k: the factor (k-1, k); empty = all
  /// per slot k: the zero-velocity factor of a stationary frame; empty =
  /// all when `imu` is empty too, none otherwise
  std::vector<char> zero_velocity;
  const std::vector<std::uint64_t>* landmarks = nullptr;  ///< feature ids; null = all initialised
};

/// The linearised window: reduced normal equations plus what the
/// back-substitution needs. Reused between solves (no allocation once sized).
class WindowProblem {
 public:
  /// Cost F(x) at the window's current estimate (see the file comment).
  [[nodiscard]] static double cost(const VioWindow& w, const WindowSolveOptions& o) {
    double F = 0.0;
    if (w.prior) F += prior_residual(w).squaredNorm();
    for (std::size_t k = 1; k < w.frames.size(); ++k)
      if (w.frames[k].imu) F += w.frames[k].imu->whitened_residual(w.frames[k - 1].x, w.frames[k].x).squaredNorm();
    for (const VioFrame& f : w.frames)
      if (f.stationary) F += f.x.v.squaredNorm() / (o.stationary_velocity_sigma_mps * o.stationary_velocity_sigma_mps);
    for (const auto& [id, l] : w.landmarks) {
      if (!l.initialised || !(l.inv_depth > 0)) continue;
      const RigidPose Ta = VioFrame::pose(w.frames[std::size_t(w.slot_of(l.obs[0].frame_id))].x);
      for (std::size_t j = 1; j < l.obs.size(); ++j) {
        const ReprojectionFactor f(l.obs[0].m, l.obs[j].m, w.sqrt_info);
        const RigidPose Tj = VioFrame::pose(w.frames[std::size_t(w.slot_of(l.obs[j].frame_id))].x);
        if (!(f.point_in_observer(Ta, Tj, w.T_bc, l.inv_depth).z() > o.min_depth)) continue;
        F += o.loss.rho(f.residual(Ta, Tj, w.T_bc, l.inv_depth).squaredNorm());
      }
    }
    return F;
  }

  /// The prior's residual \f$ r_0 + J(x \ominus \bar x) \f$ at the current estimate.
  [[nodiscard]] static Eigen::VectorXd prior_residual(const VioWindow& w) {
    const VioPrior& p = *w.prior;
    return p.linear.r0 + p.linear.J * prior_delta(w);
  }

  /// Linearises the selected factors at the current estimate: fills the
  /// camera-side H (dimension() square, before elimination), b, and the
  /// per-feature elimination data.
  void linearize(const VioWindow& w, const WindowSolveOptions& o, const WindowSelection& sel = {}) {
    const int D = w.dimension();
    H_.setZero(D, D);
    b_.setZero(D);
    ext_ = w.estimate_extrinsic ? 15 * int(w.frames.size()) : -1;
    lm_.clear();
    entries_.clear();
    first_.resize(w.frames.size());
    for (std::size_t k = 0; k < first_.size(); ++k) first_[k] = int(k);
    // Couples the keyframe blocks at offsets [oa, ob] (either may be the extrinsic: the border).
    const auto couple = [&](int oa, int ob) {
      if (oa == ext_ || ob == ext_) return;
      const int sa = oa / 15, sb = ob / 15;
      int& fa = first_[std::size_t(std::max(sa, sb))];
      fa = std::min(fa, std::min(sa, sb));
    };
    const auto lin = [&](std::size_t k) -> const ImuState& {
      const VioFrame& f = w.frames[k];
      return o.first_estimate_jacobians && f.fej ? *f.fej : f.x;
    };
    if (sel.prior && w.prior) {
      const VioPrior& p = *w.prior;
      // J^T J and J^T r0 are constant: formed once per solve (see solve()).
      if (!prior_cached_) {
        prior_JtJ_.noalias() = p.linear.J.transpose() * p.linear.J;
        prior_Jtr0_.noalias() = p.linear.J.transpose() * p.linear.r0;
      }
      // J^T r = J^T r0 + J^T J (x ⊖ x̄)
      prior_Jtr_ = prior_Jtr0_;
      prior_Jtr_.noalias() += prior_JtJ_ * prior_delta(w);
      int col = 0;
      prior_offs_.clear();
      for (const VioPriorBlock& bk : p.blocks) prior_offs_.push_back(bk.extrinsic ? ext_ : 15 * w.slot_of(bk.frame_id));
      const std::vector<int>& offs = prior_offs_;
      for (std::size_t a = 0; a < p.blocks.size(); ++a) {
        const int da = p.blocks[a].dim();
        int colb = 0;
        for (std::size_t c = 0; c < p.blocks.size(); ++c) {
          const int db = p.blocks[c].dim();
          if (offs[a] >= 0 && offs[c] >= 0) {
            H_.block(offs[a], offs[c], da, db) += prior_JtJ_.block(col, colb, da, db);
            couple(offs[a], offs[c]);
          }
          colb += db;
        }
        if (offs[a] >= 0) b_.segment(offs[a], da) += prior_Jtr_.segment(col, da);
        col += da;
      }
    }
    for (std::size_t k = 1; k < w.frames.size(); ++k) {
      if (!w.frames[k].imu || (!sel.imu.empty() && !sel.imu[k])) continue;
      const ImuFactor& fac = *w.frames[k].imu;
      ImuFactor::Jacobian Ji, Jj;
      const ImuFactor::Residual r = fac.whitened_residual(w.frames[k - 1].x, w.frames[k].x);
      (void)fac.whitened_residual(lin(k - 1), lin(k), &Ji, &Jj);
      const int oi = 15 * int(k - 1), oj = 15 * int(k);
      couple(oi, oj);
      H_.block<15, 15>(oi, oi).noalias() += Ji.transpose() * Ji;
      H_.block<15, 15>(oj, oj).noalias() += Jj.transpose() * Jj;
      H_.block<15, 15>(oi, oj).noalias() += Ji.transpose() * Jj;
      H_.block<15, 15>(oj, oi) = H_.block<15, 15>(oi, oj).transpose();
      b_.segment<15>(oi).noalias() += Ji.transpose() * r;
      b_.segment<15>(oj).noalias() += Jj.transpose() * r;
    }
    const double zv = 1.0 / (o.stationary_velocity_sigma_mps * o.stationary_velocity_sigma_mps);
    for (std::size_t k = 0; k < w.frames.size(); ++k) {
      const bool take = sel.zero_velocity.empty() ? sel.imu.empty() : sel.zero_velocity[k] != 0;
      if (!w.frames[k].stationary || !take) continue;
      const int ov = 15 * int(k) + 6;
      H_.block<3, 3>(ov, ov).diagonal().array() += zv;
      b_.segment<3>(ov).noalias() += zv * w.frames[k].x.v;
    }
    const RigidPose Tbc_lin = o.first_estimate_jacobians && w.T_bc_fej ? *w.T_bc_fej : w.T_bc;
    const auto visit = [&](std::uint64_t id, const VioLandmark& l) {
      if (!l.initialised || !(l.inv_depth > 0)) return;
      const int sa = w.slot_of(l.obs[0].frame_id);
      LandmarkBlock lb{id, 0.0, 0.0, entries_.size(), 0};
      const auto entry = [&](int off) -> Vec6& {
        for (std::size_t e = lb.first; e < entries_.size(); ++e)
          if (entries_[e].offset == off) return entries_[e].w;
        entries_.push_back(Entry{off, Vec6::Zero()});
        ++lb.count;
        return entries_.back().w;
      };
      const RigidPose Ta = VioFrame::pose(w.frames[std::size_t(sa)].x);
      const RigidPose Ta_lin = VioFrame::pose(lin(std::size_t(sa)));
      for (std::size_t j = 1; j < l.obs.size(); ++j) {
        const int sj = w.slot_of(l.obs[j].frame_id);
        const ReprojectionFactor f(l.obs[0].m, l.obs[j].m, w.sqrt_info);
        const RigidPose Tj = VioFrame::pose(w.frames[std::size_t(sj)].x);
        if (!(f.point_in_observer(Ta, Tj, w.T_bc, l.inv_depth).z() > o.min_depth)) continue;
        Eigen::Vector2d r = f.residual(Ta, Tj, w.T_bc, l.inv_depth);
        ReprojectionFactor::PoseJacobian Ja, Jj, Je;
        Eigen::Vector2d Jl;
        (void)f.residual(Ta_lin, VioFrame::pose(lin(std::size_t(sj))), Tbc_lin, l.inv_depth, &Ja, &Jj,
                         ext_ >= 0 ? &Je : nullptr, &Jl);
        const double s = o.loss.scaling(r.squaredNorm());
        r *= s;
        Ja *= s;
        Jj *= s;
        Jl *= s;
        if (ext_ >= 0) Je *= s;
        const int oa = 15 * sa, oj = 15 * sj;
        add_pose_block(oa, oa, Ja, Ja);
        add_pose_block(oj, oj, Jj, Jj);
        add_pose_block(oa, oj, Ja, Jj);
        add_pose_block(oj, oa, Jj, Ja);
        b_.segment<6>(oa).noalias() += Ja.transpose() * r;
        b_.segment<6>(oj).noalias() += Jj.transpose() * r;
        entry(oa).noalias() += Ja.transpose() * Jl;
        entry(oj).noalias() += Jj.transpose() * Jl;
        if (ext_ >= 0) {
          add_pose_block(ext_, ext_, Je, Je);
          add_pose_block(ext_, oa, Je, Ja);
          add_pose_block(oa, ext_, Ja, Je);
          add_pose_block(ext_, oj, Je, Jj);
          add_pose_block(oj, ext_, Jj, Je);
          b_.segment<6>(ext_).noalias() += Je.transpose() * r;
          entry(ext_).noalias() += Je.transpose() * Jl;
        }
        lb.h += Jl.squaredNorm();
        lb.b += Jl.dot(r);
      }
      // After the elimination the feature couples every keyframe it touches pairwise.
      int lo = ext_ >= 0 ? ext_ : 15 * int(w.frames.size());
      for (std::size_t e = lb.first; e < entries_.size(); ++e)
        if (entries_[e].offset != ext_) lo = std::min(lo, entries_[e].offset);
      for (std::size_t e = lb.first; e < entries_.size(); ++e) couple(lo, entries_[e].offset);
      if (lb.h > 0) lm_.push_back(lb);
      else entries_.resize(lb.first);
    };
    if (sel.landmarks) {
      for (const std::uint64_t id : *sel.landmarks) visit(id, w.landmarks.at(id));
    } else {
      for (const auto& [id, l] : w.landmarks) visit(id, l);
    }
  }

  /// Forms the reduced system with damping μ (the Schur complement of the
  /// file comment) into `Hs`, `bs`.
  void reduce(double mu, Eigen::MatrixXd& Hs, Eigen::VectorXd& bs) const {
    Hs = H_;
    bs = b_;
    if (mu > 0)
      for (Eigen::Index i = 0; i < Hs.rows(); ++i) Hs(i, i) += mu * std::clamp(H_(i, i), 1e-6, 1e32);
    for (const LandmarkBlock& lb : lm_) {
      const double h = damped(lb.h, mu);
      for (std::size_t a = lb.first; a < lb.first + lb.count; ++a) {
        const Entry& ea = entries_[a];
        bs.segment<6>(ea.offset) -= ea.w * (lb.b / h);
        for (std::size_t c = lb.first; c < lb.first + lb.count; ++c) {
          const Entry& ec = entries_[c];
          Hs.block<6, 6>(ea.offset, ec.offset).noalias() -= ea.w * (ec.w.transpose() / h);
        }
      }
    }
  }

  /// Solves the damped system for the camera-side step and back-substitutes
  /// the inverse depths (the file comment: profile or dense Cholesky, dense
  /// LDLT when it fails); returns false when no finite step was found.
  bool solve_step(double mu, Eigen::VectorXd& dx, std::vector<double>& dlambda) {
    const int t = ext_ >= 0 ? 6 : 0;
    reduce_lower(mu);
    dx = -bs_;
    bool ok = false;
    if (Profile::relative_work(first_, t) <= kMaxProfileWork) {
      ok = Profile::factor(Hs_, first_, t);
      if (ok) Profile::solve(Hs_, first_, t, dx);
      else reduce_lower(mu);  // factor() overwrote it
    }
    if (!ok) {
      llt_.compute(Hs_);
      if (llt_.info() == Eigen::Success) {
        llt_.solveInPlace(dx);
      } else {
        ldlt_.compute(Hs_);
        if (ldlt_.info() != Eigen::Success) return false;
        ldlt_.solveInPlace(dx);
      }
    }
    if (!dx.allFinite()) return false;
    dlambda.resize(lm_.size());
    for (std::size_t i = 0; i < lm_.size(); ++i) {
      const LandmarkBlock& lb = lm_[i];
      double acc = lb.b;
      for (std::size_t e = lb.first; e < lb.first + lb.count; ++e)
        acc += entries_[e].w.dot(dx.segment<6>(entries_[e].offset));
      dlambda[i] = -acc / damped(lb.h, mu);
    }
    return true;
  }

  /// Block row profile of the reduced system (after linearize()): for each
  /// keyframe slot, the oldest slot it is coupled to (file comment).
  [[nodiscard]] const std::vector<int>& profile() const noexcept { return first_; }

  /// Applies a step to the window's variables.
  void apply(VioWindow& w, const Eigen::VectorXd& dx, const std::vector<double>& dlambda) const {
    for (std::size_t k = 0; k < w.frames.size(); ++k) w.frames[k].x = w.frames[k].x.plus(dx.segment<15>(15 * int(k)));
    if (ext_ >= 0) w.T_bc = w.T_bc.plus(dx.segment<6>(ext_));
    for (std::size_t i = 0; i < lm_.size(); ++i) w.landmarks.at(lm_[i].id).inv_depth += dlambda[i];
  }

  /// Camera-side Hessian before elimination (after linearize()).
  [[nodiscard]] const Eigen::MatrixXd& hessian() const noexcept { return H_; }
  /// Camera-side gradient term before elimination.
  [[nodiscard]] const Eigen::VectorXd& gradient() const noexcept { return b_; }
  /// Reduced (landmarks eliminated, undamped) Hessian and gradient.
  void reduced(Eigen::MatrixXd& Hs, Eigen::VectorXd& bs) const { reduce(0.0, Hs, bs); }

  /// Re-integrates the pre-integrations whose bias moved past the thresholds (file comment).
  static int repropagate(VioWindow& w) {
    int n = 0;
    for (std::size_t k = 1; k < w.frames.size(); ++k) {
      VioFrame& f = w.frames[k];
      if (!f.imu) continue;
      if (f.pre.update_bias(w.frames[k - 1].x.bias)) {
        f.imu.emplace(f.pre, w.gravity_w);
        ++n;
      }
    }
    return n;
  }

  /// Levenberg–Marquardt on the window (file comment).
  WindowSolveSummary solve(VioWindow& w, const WindowSolveOptions& o) {
    WindowSolveSummary s;
    s.repropagated = repropagate(w);
    double F = cost(w, o);
    s.initial_cost = s.final_cost = F;
    prior_cached_ = false;
    double mu = o.initial_damping;
    bool relinearize = true;
    Eigen::VectorXd dx;
    std::vector<double> dl;
    while (s.iterations < o.max_iterations) {
      if (relinearize) {
        linearize(w, o);
        prior_cached_ = w.prior.has_value();
      }
      ++s.iterations;
      if (!solve_step(mu, dx, dl)) {
        mu *= 4.0;
        relinearize = false;
        continue;
      }
      save(w);
      apply(w, dx, dl);
      const double Ft = cost(w, o);
      if (Ft < F) {
        const double rel = (F - Ft) / std::max(F, 1e-300);
        F = Ft;
        ++s.accepted;
        mu = std::max(mu / 3.0, 1e-12);
        relinearize = true;
        if (rel < o.function_tolerance) break;
        const int rp = repropagate(w);
        if (rp > 0) {
          s.repropagated += rp;
          F = cost(w, o);
        }
      } else {
        restore(w);
        mu *= 4.0;
        relinearize = false;
        if (mu > 1e12) break;
      }
    }
    prior_cached_ = false;
    s.final_cost = F;
    return s;
  }

 private:
  using Vec6 = Eigen::Matrix<double, 6, 1>;
  struct Entry {
    int offset;
    Vec6 w;
  };
  struct LandmarkBlock {
    std::uint64_t id;
    double h, b;
    std::size_t first, count;
  };

  using Profile = detail::BlockProfileCholesky<15>;

  static double damped(double h, double mu) noexcept { return h + mu * std::clamp(h, 1e-6, 1e32); }

  /// Profile Cholesky work above this fraction of a dense one: dense LLT.
  static constexpr double kMaxProfileWork = 0.7;

  /// The damped reduced system's lower triangle (into Hs_, bs_; the strict
  /// upper triangle is not written: the factorisations read the lower one).
  void reduce_lower(double mu) {
    const Eigen::Index D = H_.rows();
    Hs_.resize(D, D);
    bs_ = b_;
    const int nb = int(first_.size());
    for (int i = 0; i < nb; ++i) {
      const int fi = first_[std::size_t(i)];
      Hs_.block(15 * i, 0, 15, 15 * fi).setZero();
      for (int j = fi; j <= i; ++j) Hs_.block<15, 15>(15 * i, 15 * j) = H_.block<15, 15>(15 * i, 15 * j);
    }
    if (ext_ >= 0) Hs_.bottomRows(D - ext_) = H_.bottomRows(D - ext_);
    if (mu > 0)
      for (Eigen::Index i = 0; i < D; ++i) Hs_(i, i) += mu * std::clamp(H_(i, i), 1e-6, 1e32);
    for (const LandmarkBlock& lb : lm_) {
      const double h = damped(lb.h, mu);
      for (std::size_t a = lb.first; a < lb.first + lb.count; ++a) {
        const Entry& ea = entries_[a];
        bs_.segment<6>(ea.offset) -= ea.w * (lb.b / h);
        const Vec6 wa = ea.w / h;
        for (std::size_t c = lb.first; c < lb.first + lb.count; ++c) {
          const Entry& ec = entries_[c];
          if (ec.offset <= ea.offset) Hs_.block<6, 6>(ea.offset, ec.offset).noalias() -= wa * ec.w.transpose();
        }
      }
    }
  }

  /// Keeps the variables a trial step changes, to undo a rejected one.
  void save(const VioWindow& w) {
    saved_x_.resize(w.frames.size());
    for (std::size_t k = 0; k < w.frames.size(); ++k) saved_x_[k] = w.frames[k].x;
    saved_T_bc_ = w.T_bc;
    saved_l_.resize(lm_.size());
    for (std::size_t i = 0; i < lm_.size(); ++i) saved_l_[i] = w.landmarks.at(lm_[i].id).inv_depth;
  }
  void restore(VioWindow& w) const {
    for (std::size_t k = 0; k < w.frames.size(); ++k) w.frames[k].x = saved_x_[k];
    w.T_bc = saved_T_bc_;
    for (std::size_t i = 0; i < lm_.size(); ++i) w.landmarks.at(lm_[i].id).inv_depth = saved_l_[i];
  }

  void add_pose_block(int oa, int ob, const Eigen::Matrix<double, 2, 6>& Ja, const Eigen::Matrix<double, 2, 6>& Jb) {
    H_.block<6, 6>(oa, ob).noalias() += Ja.transpose() * Jb;
  }

  static Eigen::VectorXd prior_delta(const VioWindow& w) {
    const VioPrior& p = *w.prior;
    Eigen::VectorXd d(p.linear.J.cols());
    int col = 0;
    for (const VioPriorBlock& bk : p.blocks) {
      if (bk.extrinsic) {
        d.segment<6>(col) = w.T_bc.minus(bk.extrinsic_ref);
      } else {
        d.segment<15>(col) = w.frames[std::size_t(w.slot_of(bk.frame_id))].x.minus(bk.frame_ref);
      }
      col += bk.dim();
    }
    return d;
  }

  Eigen::MatrixXd H_, Hs_;
  Eigen::VectorXd b_, bs_;
  int ext_ = -1;
  std::vector<LandmarkBlock> lm_;
  std::vector<Entry> entries_;
  std::vector<int> first_;  // block row profile (see profile())
  // The prior's J^T J and J^T r0, valid during one solve() (prior_cached_).
  bool prior_cached_ = false;
  Eigen::MatrixXd prior_JtJ_;
  Eigen::VectorXd prior_Jtr0_, prior_Jtr_;
  std::vector<int> prior_offs_;
  Eigen::LLT<Eigen::MatrixXd, Eigen::Lower> llt_;
  Eigen::LDLT<Eigen::MatrixXd, Eigen::Lower> ldlt_;
  std::vector<ImuState> saved_x_;
  RigidPose saved_T_bc_;
  std::vector<double> saved_l_;
};

}  // namespace posefuse
