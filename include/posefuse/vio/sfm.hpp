#pragma once
/// @file
/// Vision-only structure from motion on a window of frames, up to scale: the
/// first step of a visual-inertial initialisation from motion (VINS-Mono,
/// Qin et al., T-RO 2018, §V-A; its visual SfM).
///
/// **Input.** One list per frame (oldest first) of observations: a feature
/// id and its normalised coordinates (x/z, y/z) in that frame's camera. An id
/// names the same 3-D point in every frame that lists it.
///
/// **Procedure.**
///  1. Reference frame l: the first frame (oldest first) that shares at least
///     `min_correspondences` features with the newest frame, whose average
///     parallax with it, \f$ \phi \cdot \mathrm{mean}|m_l - m_{new}| \f$ (φ =
///     `focal_px`), is at least `min_parallax_px`, and whose relative pose
///     to it (vio/two_view.hpp, RANSAC) succeeds.
///  2. Frame l is the origin and the newest frame is at unit distance from it.
///     The two-view inliers are triangulated (vio/triangulation.hpp).
///  3. Frames l+1 ... newest-1 get their pose by PnP with RANSAC
///     (vio/pnp.hpp; the previous frame's pose as guess), each followed by
///     triangulating what it shares with the newest frame; then what frames
///     l+1 ... newest-1 share with l; then frames l-1 ... 0 by PnP (the next
///     frame as guess), each triangulated with l. Every feature still without a
///     point and seen in two posed frames is triangulated from all its views.
///     A point is kept when it lies in front of each view, its rays meet at
///     `min_triangulation_parallax_rad` or more, and it reprojects within
///     `pnp.inlier_threshold` in each view.
///  4. Bundle adjustment (vio/detail/sfm_bundle_adjustment.hpp) over all
///     poses and points (and once before step 3 over the reference pair
///     alone, so that PnP meets a structure consistent with the noise), Cauchy loss of scale `loss_scale_px`. Gauge: frame l
///     held fixed, and of the newest frame's translation step (in its own
///     frame) the coordinate along which the l–newest baseline is largest,
///     which holds the scale; the l–newest distance stays close to 1.
///     Observations then off by more than `outlier_px` (wrong associations)
///     are left out, points left with fewer than two views dropped, and the
///     adjustment run again.
///  5. Everything is re-expressed in frame 0's camera: `T_c0_c[0]` is the
///     identity, `points_c0` are in frame 0.
///
/// **Statuses** (`reason` holds a sentence whenever status != kOk):
/// kTooFewFrames (fewer than 2), kTooFewTracks (no frame shares
/// `min_correspondences` features with the newest one), kTooLittleParallax
/// (none of those has the average parallax, or the relative pose found too
/// little rotation-compensated parallax — e.g. hovering or rotating in
/// place), kDegenerate (relative pose failed otherwise, or too few points
/// triangulated), kPnpFailed (a frame could not be posed),
/// kBundleAdjustmentFailed (non-finite result or RMS reprojection error
/// above `max_rms_reprojection_px`). On failure the poses and points must not
/// be used; the caller retries when more frames arrive.

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <set>
#include <utility>
#include <span>
#include <string>
#include <vector>
#include <posefuse/core/error.hpp>
#include <posefuse/lie/se3.hpp>
#include <posefuse/vio/detail/sfm_bundle_adjustment.hpp>
#include <posefuse/vio/pnp.hpp>
#include <posefuse/vio/robust_loss.hpp>
#include <posefuse/vio/triangulation.hpp>
#include <posefuse/vio/two_view.hpp>

namespace posefuse {

/// One feature observed in one frame.
struct SfmObservation {
  std::uint64_t id;   ///< feature id, the same in every frame that sees it
  Eigen::Vector2d m;  ///< normalised coordinates (x/z, y/z)
};

/// Outcome of structure_from_motion.
enum class SfmStatus {
  kOk,
  kTooFewFrames,
  kTooFewTracks,
  kTooLittleParallax,
  kDegenerate,
  kPnpFailed,
  kBundleAdjustmentFailed
};

/// The enumerator's name without the k.
[[nodiscard]] constexpr const char* to_string(SfmStatus s) noexcept {
  switch (s) {
    case SfmStatus::kOk: return "Ok";
    case SfmStatus::kTooFewFrames: return "TooFewFrames";
    case SfmStatus::kTooFewTracks: return "TooFewTracks";
    case SfmStatus::kTooLittleParallax: return "TooLittleParallax";
    case SfmStatus::kDegenerate: return "Degenerate";
    case SfmStatus::kPnpFailed: return "PnpFailed";
    case SfmStatus::kBundleAdjustmentFailed: return "BundleAdjustmentFailed";
  }
  return "?";
}

/// Settings of structure_from_motion.
struct SfmOptions {
  double focal_px = 460;                ///< focal length for pixel thresholds, > 0
  double min_parallax_px = 30;          ///< average parallax of the reference pair, ≥ 0
  int min_correspondences = 20;         ///< features shared by the reference pair, ≥ 8
  TwoViewOptions two_view;              ///< relative pose of the reference pair
  /// Pose of the other frames. Its threshold (4 px) is looser than PnP's
  /// default: the points come from few views and carry the noise of each, so
  /// at 2 px only about half of them would be inliers and RANSAC would run
  /// hundreds of trials; the bundle adjustment refines afterwards.
  PnpOptions pnp{.inlier_threshold = 4.0 / 460.0};
  int ba_iterations = 20;               ///< bundle-adjustment iterations, ≥ 0
  double min_triangulation_parallax_rad = 1.0 / 460.0;  ///< a point's rays must meet at this angle, ≥ 0
  double loss_scale_px = 1.5;           ///< Cauchy scale of the bundle adjustment (px), > 0
  double max_rms_reprojection_px = 3.0;  ///< RMS reprojection error above this fails, > 0
  int min_points = 20;                  ///< fewer triangulated points is kDegenerate, ≥ 1
  double outlier_px = 5.0;              ///< after the adjustment, observations off by more are left out, > 0
};

/// Result of structure_from_motion.
struct SfmResult {
  SfmStatus status = SfmStatus::kTooFewFrames;  ///< see the file comment
  std::string reason;                           ///< a sentence whenever status != kOk
  std::vector<SE3d> T_c0_c;                     ///< one per frame, T_c0_c[0] = identity, up to scale
  std::map<std::uint64_t, Eigen::Vector3d> points_c0;  ///< triangulated features in frame 0's camera
  int reference_frame = -1;                     ///< l (-1 when none was found)
  double rms_reprojection_px = 0;               ///< over the kept observations of the points, after the adjustment
  int outlier_observations = 0;                 ///< observations left out (off by more than outlier_px)
};

/// Structure from motion on a window (see the file comment).
/// @param[in] frames observations per frame, oldest first
/// @param[in] o settings
/// @throws posefuse::invalid_argument on non-finite coordinates, an id listed
///         twice in one frame, or settings outside their ranges
[[nodiscard]] inline SfmResult structure_from_motion(std::span<const std::vector<SfmObservation>> frames,
                                                     const SfmOptions& o = {}) {
  if (!(o.focal_px > 0) || !(o.min_parallax_px >= 0) || o.min_correspondences < 8 || o.ba_iterations < 0 ||
      !(o.min_triangulation_parallax_rad >= 0) || !(o.loss_scale_px > 0) || !(o.max_rms_reprojection_px > 0) ||
      o.min_points < 1 || !(o.outlier_px > 0))
    throw invalid_argument("structure_from_motion: options out of range");
  const int N = int(frames.size());
  std::vector<std::map<std::uint64_t, Eigen::Vector2d>> obs(frames.size());
  for (int f = 0; f < N; ++f) {
    for (const SfmObservation& x : frames[std::size_t(f)]) {
      if (!x.m.allFinite())
        throw invalid_argument("structure_from_motion: frame " + std::to_string(f) + ", feature " +
                               std::to_string(x.id) + " is not finite");
      if (!obs[std::size_t(f)].emplace(x.id, x.m).second)
        throw invalid_argument("structure_from_motion: frame " + std::to_string(f) + " lists feature " +
                               std::to_string(x.id) + " twice");
    }
  }
  SfmResult res;
  if (N < 2) {
    res.status = SfmStatus::kTooFewFrames;
    res.reason = "SfM: " + std::to_string(N) + " frame(s), at least 2 needed.";
    return res;
  }
  const int newest = N - 1;

  // 1. Reference frame and relative pose.
  int stage = 0;  // how far the best candidate got: 1 tracks, 2 parallax, 3 two-view
  TwoViewResult tv;
  std::vector<std::uint64_t> pair_ids;
  int l = -1;
  std::string why;
  for (int f = 0; f < newest && l < 0; ++f) {
    std::vector<std::uint64_t> ids;
    std::vector<Eigen::Vector2d> ma, mb;
    double par = 0;
    for (const auto& [id, m] : obs[std::size_t(f)]) {
      const auto it = obs[std::size_t(newest)].find(id);
      if (it == obs[std::size_t(newest)].end()) continue;
      ids.push_back(id);
      ma.push_back(m);
      mb.push_back(it->second);
      par += (m - it->second).norm();
    }
    const int shared = int(ids.size());
    if (shared < o.min_correspondences) {
      if (stage <= 1) {
        stage = 1;
        why = "no frame shares " + std::to_string(o.min_correspondences) + " features with the newest one";
      }
      continue;
    }
    par = o.focal_px * par / shared;
    if (par < o.min_parallax_px) {
      if (stage <= 2) {
        stage = 2;
        why = "no frame with enough shared features has an average parallax of " +
              std::to_string(o.min_parallax_px) + " px with the newest one (frame " + std::to_string(f) + ": " +
              std::to_string(par) + " px)";
      }
      continue;
    }
    tv = solve_two_view(ma, mb, o.two_view);
    if (tv.status != TwoViewStatus::kOk) {
      stage = 3;
      why = "frame " + std::to_string(f) + " and the newest frame: " + tv.reason;
      continue;
    }
    l = f;
    for (std::size_t i = 0; i < ids.size(); ++i)
      if (tv.inlier[i]) pair_ids.push_back(ids[i]);
  }
  if (l < 0) {
    res.status = stage <= 1   ? SfmStatus::kTooFewTracks
                 : stage == 2 ? SfmStatus::kTooLittleParallax
                 : tv.status == TwoViewStatus::kTooLittleParallax ? SfmStatus::kTooLittleParallax
                                                                  : SfmStatus::kDegenerate;
    res.reason = "SfM: " + why + ".";
    return res;
  }
  res.reference_frame = l;

  // 2-3. Poses in frame l, points by triangulation, frames by PnP.
  std::vector<SE3d> T(frames.size());
  T[std::size_t(l)] = SE3d();
  T[std::size_t(newest)] = tv.T_1_2;
  std::map<std::uint64_t, Eigen::Vector3d> pts;
  TriangulationOptions topt;
  topt.min_parallax_rad = o.min_triangulation_parallax_rad;
  const auto accept = [&](std::uint64_t id, const std::vector<int>& views) {
    std::vector<SE3d> Ts;
    std::vector<Eigen::Vector2d> ms;
    for (int v : views) {
      Ts.push_back(T[std::size_t(v)]);
      ms.push_back(obs[std::size_t(v)].at(id));
    }
    const Triangulation t = triangulate_point(std::span<const SE3d>(Ts), std::span<const Eigen::Vector2d>(ms), topt);
    if (t.status != TriangulationStatus::kOk) return;
    for (std::size_t k = 0; k < Ts.size(); ++k)
      if (reprojection_residual(Ts[k], t.p_w, ms[k]).norm() > o.pnp.inlier_threshold) return;
    pts[id] = t.p_w;
  };
  const auto triangulate_pair = [&](int a, int b) {
    for (const auto& [id, m] : obs[std::size_t(a)])
      if (!pts.count(id) && obs[std::size_t(b)].count(id)) accept(id, {a, b});
  };
  for (std::uint64_t id : pair_ids) accept(id, {l, newest});
  std::map<std::uint64_t, std::vector<int>> views;
  for (int f = 0; f < N; ++f)
    for (const auto& [id, m] : obs[std::size_t(f)]) views[id].push_back(f);
  // Bundle adjustment over the frames marked in `active` and the points seen
  // by two of them; the other frames are held. Gauge: frame l, and the
  // newest frame's translation step along its largest baseline coordinate.
  const ReprojectionLoss loss{ReprojectionLoss::Kind::kCauchy, o.loss_scale_px};
  std::set<std::pair<int, std::uint64_t>> rejected;  // (frame, id) left out as outliers
  struct AdjustedPoints {
    std::vector<std::uint64_t> ids;
    std::vector<std::vector<detail::BaObservation>> obs;
  };
  const auto adjust = [&](const std::vector<char>& active, int iterations) {
    AdjustedPoints a;
    std::vector<Eigen::Vector3d> Pa;
    for (const auto& [id, p] : pts) {
      std::vector<detail::BaObservation> ob;
      for (int f : views.at(id))
        if (active[std::size_t(f)] && !rejected.count({f, id})) ob.push_back({f, obs[std::size_t(f)].at(id)});
      if (ob.size() < 2) continue;
      a.ids.push_back(id);
      a.obs.push_back(std::move(ob));
      Pa.push_back(p);
    }
    std::vector<int> held;
    for (int f = 0; f < N; ++f)
      if (f == l || !active[std::size_t(f)])
        for (int k = 0; k < 6; ++k) held.push_back(6 * f + k);
    const Eigen::Vector3d base = T[std::size_t(newest)].so3().inverse().act(T[std::size_t(newest)].translation());
    Eigen::Index axis = 0;
    base.cwiseAbs().maxCoeff(&axis);
    held.push_back(6 * newest + int(axis));
    (void)detail::bundle_adjust(T, Pa, a.obs, held, o.focal_px, loss, iterations);
    for (std::size_t j = 0; j < a.ids.size(); ++j) pts[a.ids[j]] = Pa[j];
    return a;
  };
  {  // the reference pair first, so that PnP meets a consistent structure
    std::vector<char> pair(frames.size(), 0);
    pair[std::size_t(l)] = pair[std::size_t(newest)] = 1;
    (void)adjust(pair, o.ba_iterations);
  }
  const auto pose_frame = [&](int f, int guess_frame) {
    std::vector<Eigen::Vector3d> P;
    std::vector<Eigen::Vector2d> M;
    for (const auto& [id, m] : obs[std::size_t(f)]) {
      const auto it = pts.find(id);
      if (it == pts.end()) continue;
      P.push_back(it->second);
      M.push_back(m);
    }
    const PnpResult r = solve_pnp_ransac(P, M, o.pnp, T[std::size_t(guess_frame)]);
    if (r.status != PnpStatus::kOk) {
      res.status = SfmStatus::kPnpFailed;
      res.reason = "SfM: frame " + std::to_string(f) + ": " + r.reason;
      return false;
    }
    T[std::size_t(f)] = r.T_w_c;
    return true;
  };
  for (int f = l + 1; f < newest; ++f) {
    if (!pose_frame(f, f - 1)) return res;
    triangulate_pair(f, newest);
  }
  for (int f = l + 1; f < newest; ++f) triangulate_pair(l, f);
  for (int f = l - 1; f >= 0; --f) {
    if (!pose_frame(f, f + 1)) return res;
    triangulate_pair(f, l);
  }
  for (const auto& [id, v] : views)
    if (!pts.count(id) && v.size() >= 2) accept(id, v);
  if (int(pts.size()) < o.min_points) {
    res.status = SfmStatus::kDegenerate;
    res.reason = "SfM: " + std::to_string(pts.size()) + " points triangulated, at least " +
                 std::to_string(o.min_points) + " needed.";
    return res;
  }

  // 4. Bundle adjustment over every frame; observations then off by more
  // than outlier_px are left out and the adjustment repeated.
  AdjustedPoints all = adjust(std::vector<char>(frames.size(), 1), o.ba_iterations);
  for (std::size_t j = 0; j < all.ids.size(); ++j)
    for (const detail::BaObservation& x : all.obs[j])
      if (o.focal_px * reprojection_residual(T[std::size_t(x.frame)], pts.at(all.ids[j]), x.m).norm() > o.outlier_px)
        rejected.insert({x.frame, all.ids[j]});
  if (!rejected.empty()) all = adjust(std::vector<char>(frames.size(), 1), o.ba_iterations);
  res.outlier_observations = int(rejected.size());
  const std::vector<std::uint64_t>& ids = all.ids;
  std::vector<Eigen::Vector3d> P;
  for (std::uint64_t id : ids) P.push_back(pts.at(id));
  const std::vector<std::vector<detail::BaObservation>>& ob = all.obs;

  double ss = 0;
  std::size_t n_obs = 0;
  bool finite = true;
  for (std::size_t j = 0; j < P.size(); ++j) {
    finite = finite && P[j].allFinite();
    for (const detail::BaObservation& x : ob[j]) {
      ss += (o.focal_px * reprojection_residual(T[std::size_t(x.frame)], P[j], x.m)).squaredNorm();
      ++n_obs;
    }
  }
  for (const SE3d& t : T) finite = finite && t.translation().allFinite();
  res.rms_reprojection_px = n_obs > 0 ? std::sqrt(ss / double(n_obs)) : 0.0;
  if (!finite || !(res.rms_reprojection_px <= o.max_rms_reprojection_px)) {
    res.status = SfmStatus::kBundleAdjustmentFailed;
    res.reason = "SfM: after the bundle adjustment the RMS reprojection error is " +
                 std::to_string(res.rms_reprojection_px) + " px, above " + std::to_string(o.max_rms_reprojection_px) +
                 " px" + (finite ? "." : " (non-finite result).");
    return res;
  }

  // 5. Frame 0 as the origin.
  const SE3d T_0_l = T[0].inverse();
  res.T_c0_c.resize(frames.size());
  for (int f = 0; f < N; ++f) res.T_c0_c[std::size_t(f)] = T_0_l * T[std::size_t(f)];
  res.T_c0_c[0] = SE3d();
  for (std::size_t j = 0; j < P.size(); ++j) res.points_c0[ids[j]] = T_0_l.act(P[j]);
  res.status = SfmStatus::kOk;
  return res;
}

}  // namespace posefuse
