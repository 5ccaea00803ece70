#pragma once
/// @file
/// Sliding the visual-inertial window (vio/window_state.hpp): feature
/// triangulation, the keyframe test, VINS-Mono's two marginalisation
/// policies, and outlier removal after a solve.
///
/// **Keyframe test** (Qin et al., "VINS-Mono", T-RO 2018, Sec. IV-B). A
/// frame is a keyframe when it tracks fewer than `min_tracked` of the
/// features of the frame before, or when the mean parallax of the shared
/// features is at least `min_parallax_px` and at least
/// `min_keyframe_interval_s` have passed since the frame before. With
/// `rotation_compensated_parallax` (the default) the rotation between the two
/// frames is removed first: the older frame's bearing $ m_a $ is rotated
/// into the newer camera by the pre-integrated gyro rotation
/// $ \Delta R_{ab} $ of the newer frame (it covers exactly the two
/// frames) and the extrinsic, $ m_a' = \pi(R_{bc}^	op \Delta R_{ab}^	op
/// R_{bc}\, [m_a; 1]) $, and the parallax is $ |m_b - m_a'| $: a pure
/// rotation has none, so only translation — what the window needs to
/// triangulate — makes keyframes. Off, the parallax is the raw $ |m_b - m_a| $.
///
/// **Policies** (Qin et al., "VINS-Mono", T-RO 2018, Sec. VI-D). When the
/// second newest frame is a keyframe (the test above) the oldest keyframe is
/// marginalised:
/// its state, the inverse depths anchored at it and every factor touching
/// them (the prior, the IMU factor to the next keyframe, their reprojection
/// residuals) are linearised (first-estimate Jacobians for variables already
/// in the prior, vio/window_problem.hpp), the landmarks are eliminated, and
/// the Schur complement becomes the new prior (graph/marginalization.hpp:
/// eigenvalues clamped, so the prior stays PSD). Otherwise the second newest
/// frame is dropped: its reprojection residuals are discarded, its two
/// pre-integrations are merged into one (the samples are re-integrated), and,
/// when the prior involves it, its state is marginalised out of the prior
/// alone (exact, the prior being linear).
///
/// **Tracks of marginalised landmarks.** As in VINS-Mono, a feature anchored
/// at the marginalised keyframe that is still observed by later keyframes is
/// re-anchored at its next observation (its inverse depth transferred) and
/// stays in the window with those observations, which the prior has already
/// used once (`reuse_marginalised_tracks`; off, the feature restarts from
/// its next new observation and no measurement is used twice).
///
/// **Outliers.** After a solve, an observation whose reprojection error
/// exceeds `outlier_threshold_px` is removed; a feature whose anchor
/// observation is the bad one, or whose inverse depth is not positive, is
/// removed entirely (its id may start a new feature later).

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include <posefuse/graph/marginalization.hpp>
#include <posefuse/vio/window_problem.hpp>

namespace posefuse {

/// Options of the window's sliding (see the file comment).
struct SlidingWindowOptions {
  /// Keyframes kept, the newest frame not counted. With the keyframe
  /// interval below, 10 keyframes span about 2.5 s: on semi-real EuRoC V1_01
  /// the position+yaw APE is 0.059 m at 9.9 ms per frame, against 0.103 m
  /// with no interval (0.6 s) and 0.062 m with 20 keyframes and no interval
  /// (1.4 s, 37 ms per frame); docs/vio.md has the table.
  int window_size = 10;
  double min_parallax_px = 10.0;             ///< keyframe test: mean parallax (px at the focal length)
  /// Keyframe test: remove the gyro's rotation between the two frames before
  /// measuring parallax (file comment); false: the raw displacement.
  bool rotation_compensated_parallax = true;
  /// Keyframe test: the parallax test makes no keyframe sooner than this
  /// after the frame before (s); losing track (`min_tracked`) still does.
  /// 0.25 s makes the window span seconds, so that the scale rests on
  /// seconds of accelerometer rather than one.
  double min_keyframe_interval_s = 0.25;
  int min_tracked = 20;                      ///< keyframe test: fewer shared features makes a keyframe
  /// Focal length (px) that converts parallax to pixels; VioEstimator sets
  /// it (and the start's SfM's) to the camera's mean of fu and fv, so a
  /// value given here matters only to direct callers of the window functions.
  double focal_px = 460.0;
  double pixel_sigma_px = 1.0;               ///< σ of the reprojection residuals
  /// Reprojection error above this is an outlier: the 99.9 % bound of χ²(2)
  /// for a residual of variance 2σ² per axis (the anchor's pixel noise and
  /// the observer's), \f$ \sqrt{2 \cdot 13.82}\,\sigma = 5.26\,\sigma \f$ at σ = 1 px.
  double outlier_threshold_px = 5.26;
  double min_depth_m = 0.1;                  ///< triangulation: nearest accepted point
  double max_depth_m = 200.0;                ///< triangulation: farthest accepted point
  double min_ray_angle_rad = 0.5 * 3.14159265358979 / 180.0;  ///< triangulation: least ray angle
  bool reuse_marginalised_tracks = true;     ///< see the file comment
  /// Rest test (is_stationary): the median image displacement of the shared
  /// features is below this many pixel σ (pure noise gives a median of 1.67 σ).
  double stationary_displacement_sigmas = 2.5;
  WindowSolveOptions solve;                  ///< the LM solve
};

/// Initialises every feature with two or more observations and no depth yet.
/// @return how many were initialised
inline int triangulate_features(VioWindow& w, const SlidingWindowOptions& o) {
  int n = 0;
  for (auto& [id, l] : w.landmarks) {
    if (l.initialised || l.obs.size() < 2) continue;
    if (const auto ld = triangulate_inverse_depth(w, l, o.min_depth_m, o.max_depth_m, o.min_ray_angle_rad)) {
      l.inv_depth = *ld;
      l.initialised = true;
      ++n;
    }
  }
  return n;
}

/// Calls f(m_a, m_b) (normalised coordinates) for every landmark seen in
/// both frames `a` and `b`, in the window's landmark order.
template <class F>
void for_each_shared_pair(const VioWindow& w, std::uint64_t a, std::uint64_t b, F f) {
  for (const auto& [id, l] : w.landmarks) {
    const VioObservation* oa = nullptr;
    const VioObservation* ob = nullptr;
    for (const VioObservation& o : l.obs) {
      if (o.frame_id == a) oa = &o;
      if (o.frame_id == b) ob = &o;
    }
    if (oa && ob) f(oa->m, ob->m);
  }
}

/// Mean parallax (px at the focal length) of the features seen by both the
/// frame at `slot` and the frame at `slot - 1`, and their number. With
/// `rotation_compensated` the pre-integrated rotation of frames[slot].pre
/// (which spans the two frames) is removed first (file comment).
/// `flip_compensation` applies the inverse rotation instead — wrong, for tests.
[[nodiscard]] inline std::pair<double, int> mean_parallax(const VioWindow& w, std::size_t slot, double focal_px,
                                                          bool rotation_compensated,
                                                          bool flip_compensation = false) {
  if (slot == 0 || slot >= w.frames.size()) return {0.0, 0};
  // R_{c_b c_a} = R_bc^T ΔR_ab^T R_bc maps a direction of camera a into camera b.
  const SO3d dR = w.frames[slot].pre.delta().R;
  const SO3d R_ba = w.T_bc.R.inverse().compose((flip_compensation ? dR : dR.inverse()).compose(w.T_bc.R));
  const Eigen::Matrix3d M = R_ba.matrix();
  const std::uint64_t a = w.frames[slot - 1].id, b = w.frames[slot].id;
  double sum = 0.0;
  int shared = 0;
  for_each_shared_pair(w, a, b, [&](const Eigen::Vector2d& m_a, const Eigen::Vector2d& m_b) {
    Eigen::Vector2d ma = m_a;
    if (rotation_compensated) {
      const Eigen::Vector3d r = M * Eigen::Vector3d(ma.x(), ma.y(), 1.0);
      // Behind the newer camera after rotation: no meaningful image displacement.
      if (!(r.z() > 1e-6)) return;
      ma = r.head<2>() / r.z();
    }
    sum += (m_b - ma).norm();
    ++shared;
  });
  return {shared > 0 ? sum / shared * focal_px : 0.0, shared};
}

/// The keyframe test of the file comment for the frame at `slot` against `slot - 1`.
[[nodiscard]] inline bool is_keyframe(const VioWindow& w, std::size_t slot, const SlidingWindowOptions& o) {
  if (slot == 0) return true;
  const auto [parallax, shared] = mean_parallax(w, slot, o.focal_px, o.rotation_compensated_parallax);
  if (shared < o.min_tracked) return true;
  if (o.min_keyframe_interval_s > 0 &&
      double(w.frames[slot].t_ns - w.frames[slot - 1].t_ns) * 1e-9 < o.min_keyframe_interval_s)
    return false;
  return parallax >= o.min_parallax_px;
}

/// Rest test of the frame at `slot` against the keyframe at `ref`: at least
/// `min_tracked` features seen in both, and the median of their displacements
/// (px at the focal length) below `stationary_displacement_sigmas` pixel σ —
/// what pixel noise alone explains (the median of the displacement of a
/// point that does not move is \f$ \sqrt{2\ln 4}\,\sigma \approx 1.67\sigma \f$). The median, not the mean, so that
/// wrong associations do not decide. Comparing against the last keyframe
/// rather than the previous image lets slow motion accumulate until it shows.
[[nodiscard]] inline bool is_stationary(const VioWindow& w, std::size_t ref, std::size_t slot,
                                        const SlidingWindowOptions& o) {
  if (ref >= slot || slot >= w.frames.size()) return false;
  std::vector<double> d;
  for_each_shared_pair(w, w.frames[ref].id, w.frames[slot].id,
                       [&](const Eigen::Vector2d& ma, const Eigen::Vector2d& mb) { d.push_back((ma - mb).norm() * o.focal_px); });
  if (int(d.size()) < o.min_tracked) return false;
  const auto mid = d.begin() + std::ptrdiff_t(d.size() / 2);
  std::nth_element(d.begin(), mid, d.end());
  return *mid < o.stationary_displacement_sigmas * o.pixel_sigma_px;
}

/// Marginalises the oldest keyframe (file comment).
inline void marginalize_oldest(VioWindow& w, const SlidingWindowOptions& o, WindowProblem& P) {
  if (w.frames.size() < 2) return;
  const std::uint64_t old_id = w.frames[0].id;
  std::vector<std::uint64_t> gone;
  for (const auto& [id, l] : w.landmarks)
    if (l.initialised && l.obs.front().frame_id == old_id && l.obs.size() >= 2) gone.push_back(id);
  WindowSelection sel;
  sel.imu.assign(w.frames.size(), 0);
  sel.imu[1] = 1;
  sel.zero_velocity.assign(w.frames.size(), 0);
  sel.zero_velocity[0] = 1;
  sel.landmarks = &gone;
  P.linearize(w, o.solve, sel);
  Eigen::MatrixXd Hs;
  Eigen::VectorXd bs;
  P.reduced(Hs, bs);
  // The blocks the selected factors touch: keyframe slots, then the extrinsic.
  struct Block {
    int offset, dim, slot;  // slot -1: extrinsic
  };
  std::vector<Block> blocks;
  const auto touched = [&](int off, int dim) { return Hs.block(off, off, dim, dim).cwiseAbs().maxCoeff() > 0.0; };
  for (std::size_t k = 0; k < w.frames.size(); ++k)
    if (k == 0 || touched(15 * int(k), 15)) blocks.push_back(Block{15 * int(k), 15, int(k)});
  if (w.estimate_extrinsic && touched(15 * int(w.frames.size()), 6))
    blocks.push_back(Block{15 * int(w.frames.size()), 6, -1});
  int n = 0;
  for (const Block& bk : blocks) n += bk.dim;
  Eigen::MatrixXd H(n, n);
  Eigen::VectorXd b(n);
  int r = 0;
  for (const Block& a : blocks) {
    int c = 0;
    for (const Block& d : blocks) {
      H.block(r, c, a.dim, d.dim) = Hs.block(a.offset, d.offset, a.dim, d.dim);
      c += d.dim;
    }
    b.segment(r, a.dim) = bs.segment(a.offset, a.dim);
    r += a.dim;
  }
  H = (0.5 * (H + H.transpose())).eval();
  std::vector<int> remove(15);
  for (int i = 0; i < 15; ++i) remove[std::size_t(i)] = i;  // slot 0 is the first block
  std::optional<VioPrior> next;
  if (blocks.size() > 1) {
    next.emplace();
    next->linear = marginalize(H, b, remove);
    for (std::size_t q = 1; q < blocks.size(); ++q) {
      VioPriorBlock pb;
      if (blocks[q].slot < 0) {
        pb.extrinsic = true;
        pb.extrinsic_ref = w.T_bc;
        if (!w.T_bc_fej) w.T_bc_fej = w.T_bc;
      } else {
        VioFrame& f = w.frames[std::size_t(blocks[q].slot)];
        pb.frame_id = f.id;
        pb.frame_ref = f.x;
        if (!f.fej) f.fej = f.x;
      }
      next->blocks.push_back(pb);
    }
    if (next->linear.J.rows() == 0) next.reset();
  }
  w.prior = std::move(next);
  for (auto it = w.landmarks.begin(); it != w.landmarks.end();) {
    VioLandmark& l = it->second;
    if (l.obs.front().frame_id != old_id) {
      ++it;
      continue;
    }
    const bool was_used = l.initialised && l.obs.size() >= 2;
    if (was_used && !o.reuse_marginalised_tracks) {
      it = w.landmarks.erase(it);
      continue;
    }
    (void)reanchor_landmark(w, l);
    if (l.obs.empty()) it = w.landmarks.erase(it);
    else ++it;
  }
  w.frames.erase(w.frames.begin());
  w.frames.front().imu.reset();
  w.frames.front().pre = Preintegration(w.frames.front().pre.noise(), w.frames.front().x.bias,
                                        w.frames.front().pre.options());
}

/// Drops the second newest frame (file comment).
inline void drop_second_newest(VioWindow& w) {
  if (w.frames.size() < 3) return;
  const std::size_t s = w.frames.size() - 2;
  const std::uint64_t id = w.frames[s].id;
  if (w.prior) {
    VioPrior& p = *w.prior;
    int col = 0, at = -1;
    std::size_t which = 0;
    for (std::size_t q = 0; q < p.blocks.size(); ++q) {
      if (!p.blocks[q].extrinsic && p.blocks[q].frame_id == id) {
        at = col;
        which = q;
      }
      col += p.blocks[q].dim();
    }
    if (at >= 0) {
      const Eigen::MatrixXd H = p.linear.J.transpose() * p.linear.J;
      const Eigen::VectorXd b = p.linear.J.transpose() * p.linear.r0;
      std::vector<int> remove(15);
      for (int i = 0; i < 15; ++i) remove[std::size_t(i)] = at + i;
      if (p.blocks.size() == 1) {
        w.prior.reset();
      } else {
        p.linear = marginalize(H, b, remove);
        p.blocks.erase(p.blocks.begin() + std::ptrdiff_t(which));
        if (p.linear.J.rows() == 0) w.prior.reset();
      }
    }
  }
  for (auto it = w.landmarks.begin(); it != w.landmarks.end();) {
    VioLandmark& l = it->second;
    if (l.obs.front().frame_id == id) {
      (void)reanchor_landmark(w, l);
    } else {
      l.obs.erase(std::remove_if(l.obs.begin(), l.obs.end(), [id](const VioObservation& ob) { return ob.frame_id == id; }),
                  l.obs.end());
      if (l.obs.size() < 2) l.initialised = false;
    }
    if (l.obs.empty()) it = w.landmarks.erase(it);
    else ++it;
  }
  VioFrame& dropped = w.frames[s];
  VioFrame& newest = w.frames[s + 1];
  if (dropped.imu) {
    Preintegration merged = dropped.pre;
    const auto more = newest.pre.samples();
    for (std::size_t k = 1; k < more.size(); ++k) (void)merged.add(more[k]);
    newest.pre = std::move(merged);
    newest.imu.emplace(newest.pre, w.gravity_w);
  } else {
    newest.imu.reset();
  }
  w.frames.erase(w.frames.begin() + std::ptrdiff_t(s));
}

/// Removes outlier observations and features (file comment).
/// @return observations removed (a removed feature counts all of its)
inline int remove_outliers(VioWindow& w, const SlidingWindowOptions& o) {
  int removed = 0;
  const double thr = o.outlier_threshold_px / o.pixel_sigma_px;  // in units of σ
  for (auto it = w.landmarks.begin(); it != w.landmarks.end();) {
    VioLandmark& l = it->second;
    if (!l.initialised) {
      ++it;
      continue;
    }
    bool drop = !(l.inv_depth > 0);
    const RigidPose Ta = VioFrame::pose(w.frames[std::size_t(w.slot_of(l.obs[0].frame_id))].x);
    std::vector<char> bad(l.obs.size(), 0);
    int nbad = 0;
    for (std::size_t j = 1; j < l.obs.size() && !drop; ++j) {
      const ReprojectionFactor f(l.obs[0].m, l.obs[j].m, w.sqrt_info);
      const RigidPose Tj = VioFrame::pose(w.frames[std::size_t(w.slot_of(l.obs[j].frame_id))].x);
      const bool behind = !(f.point_in_observer(Ta, Tj, w.T_bc, l.inv_depth).z() > o.solve.min_depth);
      if (behind || f.residual(Ta, Tj, w.T_bc, l.inv_depth).norm() > thr) {
        bad[j] = 1;
        ++nbad;
      }
    }
    // Every other observation bad: the anchor is the likelier culprit.
    if (drop || (nbad > 0 && nbad + 1 >= int(l.obs.size()) && l.obs.size() >= 3)) {
      removed += int(l.obs.size());
      it = w.landmarks.erase(it);
      continue;
    }
    if (nbad > 0) {
      std::vector<VioObservation> kept;
      for (std::size_t j = 0; j < l.obs.size(); ++j)
        if (!bad[j]) kept.push_back(l.obs[j]);
      l.obs = std::move(kept);
      removed += nbad;
      if (l.obs.size() < 2) l.initialised = false;
    }
    ++it;
  }
  return removed;
}

}  // namespace posefuse
