#pragma once
/// @file
/// A seeded feature-track simulator: what a visual front end would report
/// for a camera moving along a given trajectory through a room of point
/// landmarks. With a real ground truth (EuRoC `groundtruth_20hz.csv`) and the
/// real IMU beside it, the tracks make **semi-real** sequences: real IMU,
/// real motion, synthetic vision.
///
/// **Scene.** The camera poses are \f$ T_{WC} = T_{WB}\,T_{BS} \f$ (T_BS of
/// the camera). The room is the bounding box of the camera positions grown
/// by `room_margin_m` on every side (world axes); `wall_density_per_m2`
/// landmarks per m² are spread uniformly on its six faces. Then
/// `free_points` free landmarks: each on the ray of a uniformly random pixel
/// of a uniformly random frame, at a camera depth uniform in
/// [`free_depth_min_m`, `free_depth_max_m`], kept when inside the room
/// (0.1 m from the walls; up to 20 draws each). Occlusion is not modelled.
///
/// **Tracking**, frame by frame at the frame stamps: every landmark is
/// projected (PinholeRadtan::project: in front, inside the image, within
/// the distortion's valid radius) and seen when its camera depth is at
/// least `min_depth_m`. A track goes on while its landmark is seen and it
/// is shorter than its own length limit, drawn uniformly from
/// [⌈max/2⌉, max] frames (`max_track_length`) so that tracks do not all end
/// together. When fewer than `features_per_frame` tracks go on, new ones
/// start on seen, untracked landmarks in a random order, each at least
/// `min_feature_distance_px` from every other tracked feature (as a front
/// end's detection mask); a track gets the next id (0, 1, 2, ...) with its
/// first written observation: ids are never reused (a landmark seen again
/// after its track ended gets a new id) and every id appears in the output.
/// With `recurring_ids` a track's id is instead its landmark's index, so a
/// landmark seen again, seconds or minutes later, comes back under the same
/// id: the data association a place-recognition front end would find, given
/// here by the simulation itself (an oracle: perfect, with no false matches
/// beyond the wrong associations below).
///
/// **Observations.** Each observation is, with probability
/// `outlier_fraction` and independently of the others, a **wrong
/// association**: its pixel is the projection of another landmark seen in
/// the same frame (one at least `outlier_min_error_px` from the true pixel;
/// when 10 random picks find none, a uniformly random pixel of the image at
/// least that far), kept under the track's id — what a tracker that jumped
/// to a neighbouring corner reports. Then independent N(0, σ²) noise
/// (`pixel_noise_px`) is added to u and v. An observation whose noisy pixel
/// falls outside the image ends its track (it is not written). With σ = 0
/// and no wrong associations the pixels are exact projections.
///
/// **Determinism.** One mt19937_64 seeded with `seed`, with its own uniform
/// and Box-Muller normal (no std::normal_distribution), draws in a fixed
/// order: a seed gives the same tracks, bit for bit, with every standard
/// library for one compiler and one set of flags. Another compiler may round
/// a product differently, move a border pixel in or out of the image and so
/// shift every later draw; the statistics do not change.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include <posefuse/core/error.hpp>
#include <posefuse/core/interpolation.hpp>
#include <posefuse/core/time.hpp>
#include <posefuse/io/detail/message_number.hpp>
#include <posefuse/io/euroc.hpp>
#include <posefuse/sim/detail/feature_track_scene.hpp>
#include <posefuse/sim/imu.hpp>
#include <posefuse/vio/camera.hpp>
#include <posefuse/vio/feature_tracks.hpp>

namespace posefuse::sim {

/// Parameters of the track simulator (file comment); every default stated.
struct TrackSimConfig {
  double rate_hz = 20.0;                ///< frame rate (Hz)
  double pixel_noise_px = 1.0;          ///< σ of the pixel noise, per axis (px)
  double outlier_fraction = 0.05;       ///< probability that an observation is a wrong association
  double outlier_min_error_px = 10.0;   ///< a wrong association is at least this far from the truth (px)
  int features_per_frame = 150;         ///< tracked features wanted in every frame
  int max_track_length = 60;            ///< longest track (frames); each track's limit in [⌈max/2⌉, max]
  double min_feature_distance_px = 20.0;  ///< a new track starts at least this far from the others (px)
  double min_depth_m = 0.3;             ///< landmarks nearer the camera (z) are not seen (m)
  double room_margin_m = 2.0;           ///< walls this far beyond the camera path's bounding box (m)
  double wall_density_per_m2 = 8.0;     ///< landmarks per m² on the walls, floor and ceiling
  int free_points = 2000;               ///< free landmarks inside the room
  double free_depth_min_m = 1.0;        ///< free landmarks' camera depth, lower end (m)
  double free_depth_max_m = 4.0;        ///< free landmarks' camera depth, upper end (m)
  /// Frames that would interpolate the ground truth across an interval
  /// longer than this are refused (s); for simulate_feature_tracks(EurocGroundTruth).
  double max_pose_gap_s = 0.1;
  std::uint64_t seed = 1;               ///< random seed
  /// A landmark keeps its id (its index) whenever it is seen again: loop
  /// closures by an oracle (file comment). Off: every track gets a new id.
  bool recurring_ids = false;

  /// @throws posefuse::invalid_argument naming the first bad parameter
  void validate() const {
    const auto bad = [](const std::string& what) {
      throw invalid_argument("TrackSimConfig: " + what);
    };
    if (!(rate_hz > 0 && std::isfinite(rate_hz))) bad("rate_hz must be finite and > 0");
    if (!(pixel_noise_px >= 0 && std::isfinite(pixel_noise_px))) bad("pixel_noise_px must be finite and >= 0");
    if (!(outlier_fraction >= 0 && outlier_fraction < 1)) bad("outlier_fraction must be in [0, 1)");
    if (!(outlier_min_error_px >= 0 && std::isfinite(outlier_min_error_px)))
      bad("outlier_min_error_px must be finite and >= 0");
    if (features_per_frame < 1) bad("features_per_frame must be >= 1");
    if (max_track_length < 2) bad("max_track_length must be >= 2");
    if (!(min_feature_distance_px >= 0 && std::isfinite(min_feature_distance_px)))
      bad("min_feature_distance_px must be finite and >= 0");
    if (!(min_depth_m > 0 && std::isfinite(min_depth_m))) bad("min_depth_m must be finite and > 0");
    if (!(room_margin_m > 0 && std::isfinite(room_margin_m))) bad("room_margin_m must be finite and > 0");
    if (!(wall_density_per_m2 >= 0 && std::isfinite(wall_density_per_m2)))
      bad("wall_density_per_m2 must be finite and >= 0");
    if (free_points < 0) bad("free_points must be >= 0");
    if (!(free_depth_min_m > 0 && free_depth_min_m <= free_depth_max_m && std::isfinite(free_depth_max_m)))
      bad("free depths must satisfy 0 < free_depth_min_m <= free_depth_max_m < inf");
    if (!(max_pose_gap_s > 0 && std::isfinite(max_pose_gap_s))) bad("max_pose_gap_s must be finite and > 0");
  }
};

/// What the simulation knows about one observation.
struct ObservationTruth {
  std::size_t landmark = 0;                           ///< the track's landmark (index into landmarks_w)
  Eigen::Vector2d uv_true = Eigen::Vector2d::Zero();  ///< its exact projection (px)
  bool wrong_association = false;                     ///< the pixel is another landmark's or random
};

/// The simulated tracks and the truth behind them.
struct SimulatedTracks {
  FeatureTracks tracks;  ///< what a front end would write (frames with no feature are kept, empty)
  /// truth[k][i] is about tracks[k].features[i].
  std::vector<std::vector<ObservationTruth>> truth;
  std::vector<Eigen::Isometry3d> T_W_B;       ///< body pose at each frame
  std::vector<Eigen::Vector3d> landmarks_w;   ///< landmarks: walls first, then free points (m)
  std::size_t wall_landmarks = 0;             ///< landmarks_w[0, wall_landmarks) lie on walls
  /// landmark_of_id[id]: the landmark of track id (one per track; with
  /// recurring_ids the identity over every landmark, as ids are landmarks)
  std::vector<std::size_t> landmark_of_id;
  std::size_t observations = 0;               ///< observations written
  std::size_t wrong_associations = 0;         ///< of which wrong associations
  std::size_t frames_below_target = 0;        ///< frames with fewer than features_per_frame features
};

/// Most landmarks and most observations one simulation may hold (about
/// 0.5 GB each); a larger scene or output is refused before anything is
/// allocated (track_simulation_size).
inline constexpr double kMaxSimulatedLandmarks = 1e7;
inline constexpr double kMaxSimulatedObservations = 1e7;

/// How large a simulation would be, estimated before it allocates anything.
struct TrackSimSize {
  double frames = 0;            ///< frame stamps
  double wall_landmarks = 0;    ///< landmarks on the six faces of the room
  double landmarks = 0;         ///< walls and free points
  double max_observations = 0;  ///< frames x features_per_frame (an upper bound)
  /// True when both counts are within kMaxSimulatedLandmarks and
  /// kMaxSimulatedObservations.
  [[nodiscard]] bool fits() const noexcept {
    return landmarks <= kMaxSimulatedLandmarks && max_observations <= kMaxSimulatedObservations;
  }
};

/// The size of a simulation of `frames` frames whose camera positions span
/// the box [path_lo, path_hi] (world axes), as simulate_feature_tracks
/// builds it (room = the box grown by room_margin_m).
[[nodiscard]] inline TrackSimSize track_simulation_size(double frames, const Eigen::Vector3d& path_lo,
                                                        const Eigen::Vector3d& path_hi,
                                                        const TrackSimConfig& config) {
  TrackSimSize s;
  s.frames = frames;
  const Eigen::Vector3d size = (path_hi - path_lo).array() + 2.0 * config.room_margin_m;
  for (int axis = 0; axis < 3; ++axis)
    s.wall_landmarks += 2.0 * size((axis + 1) % 3) * size((axis + 2) % 3) * config.wall_density_per_m2;
  s.landmarks = s.wall_landmarks + double(std::max(config.free_points, 0));
  s.max_observations = frames * double(std::max(config.features_per_frame, 0));
  return s;
}

/// Frame stamps t_first + k * round(1e9 / rate) ns, up to t_last.
/// @throws posefuse::invalid_argument for a bad rate or t_last < t_first
[[nodiscard]] inline std::vector<std::int64_t> frame_stamps(std::int64_t t_first_ns, std::int64_t t_last_ns,
                                                            double rate_hz) {
  if (!(rate_hz > 0 && rate_hz <= 1e6)) throw invalid_argument("frame_stamps: rate must be in (0, 1e6] Hz");
  if (t_last_ns < t_first_ns) throw invalid_argument("frame_stamps: the last stamp is before the first");
  const std::int64_t step = std::llround(1e9 / rate_hz);
  std::vector<std::int64_t> t;
  for (std::int64_t k = 0; k <= (t_last_ns - t_first_ns) / step; ++k) t.push_back(t_first_ns + k * step);
  return t;
}

/// Simulates tracks for body poses T_W_B at stamps t_ns (file comment).
/// @param[in] t_ns   frame stamps, strictly increasing
/// @param[in] T_W_B  body poses at those stamps (same count)
/// @param[in] camera the camera (intrinsics, distortion, T_BS)
/// @param[in] config parameters
/// @throws posefuse::invalid_argument for a bad config or camera, empty or
///         mismatched inputs, or stamps that do not increase
[[nodiscard]] inline SimulatedTracks simulate_feature_tracks(const std::vector<std::int64_t>& t_ns,
                                                             const std::vector<Eigen::Isometry3d>& T_W_B,
                                                             const PinholeRadtan& camera,
                                                             const TrackSimConfig& config) {
  config.validate();
  camera.validate();
  if (t_ns.empty() || t_ns.size() != T_W_B.size())
    throw invalid_argument("simulate_feature_tracks: need as many poses as stamps (and at least one)");
  for (std::size_t k = 1; k < t_ns.size(); ++k)
    if (!(t_ns[k] > t_ns[k - 1])) throw invalid_argument("simulate_feature_tracks: stamps must increase");

  detail::SeededRng rng(config.seed);
  SimulatedTracks out;
  std::vector<Eigen::Isometry3d> T_W_C;
  T_W_C.reserve(T_W_B.size());
  for (const Eigen::Isometry3d& T : T_W_B) T_W_C.push_back(T * camera.T_BS);
  const detail::Room room = detail::room_around(T_W_C, config.room_margin_m);
  {
    const TrackSimSize size = track_simulation_size(double(t_ns.size()), room.lo.array() + config.room_margin_m,
                                                    room.hi.array() - config.room_margin_m, config);
    if (!size.fits())
      throw invalid_argument("the simulation would hold about " + posefuse::detail::message_number(size.landmarks) +
                             " landmarks and up to " + posefuse::detail::message_number(size.max_observations) +
                             " observations (limits " + posefuse::detail::message_number(kMaxSimulatedLandmarks) + " and " +
                             posefuse::detail::message_number(kMaxSimulatedObservations) + ")");
  }
  out.T_W_B = T_W_B;
  detail::add_wall_landmarks(room, config.wall_density_per_m2, rng, out.landmarks_w);
  out.wall_landmarks = out.landmarks_w.size();
  detail::add_free_landmarks(T_W_C, camera, room, std::size_t(config.free_points), config.free_depth_min_m,
                             config.free_depth_max_m, rng, out.landmarks_w);

  struct Track {
    std::size_t landmark;
    std::uint64_t id;
    int length, limit;
  };
  const std::size_t L = out.landmarks_w.size();
  if (config.recurring_ids)
    for (std::size_t i = 0; i < L; ++i) out.landmark_of_id.push_back(i);
  std::vector<Eigen::Vector2d> proj(L);
  std::vector<char> seen(L, 0), tracked(L, 0);
  std::vector<std::size_t> visible, candidates;
  std::vector<Track> active, next;
  detail::PixelGrid grid(camera.width, camera.height, config.min_feature_distance_px);
  const int limit_lo = (config.max_track_length + 1) / 2;
  const auto target = std::size_t(config.features_per_frame);
  const double sigma = config.pixel_noise_px, min_err = config.outlier_min_error_px;

  // A box around the image's undistorted border (2 % wider): points outside
  // it cannot project into the image, so most are rejected before project().
  double x_max = 0, y_max = 0;
  for (int i = 0; i <= 64; ++i) {
    const double a = i / 64.0;
    for (const Eigen::Vector2d& uv :
         {Eigen::Vector2d(-0.5 + a * camera.width, -0.5), Eigen::Vector2d(-0.5 + a * camera.width, camera.height - 0.5),
          Eigen::Vector2d(-0.5, -0.5 + a * camera.height), Eigen::Vector2d(camera.width - 0.5, -0.5 + a * camera.height)}) {
      const Eigen::Vector2d xy = camera.undistort(uv);
      x_max = std::max(x_max, 1.02 * std::abs(xy.x()));
      y_max = std::max(y_max, 1.02 * std::abs(xy.y()));
    }
  }
  out.tracks.reserve(t_ns.size());
  out.truth.reserve(t_ns.size());
  for (std::size_t k = 0; k < t_ns.size(); ++k) {
    const Eigen::Matrix3d R_CW = T_W_C[k].linear().transpose();
    const Eigen::Vector3d c_W = T_W_C[k].translation();
    visible.clear();
    for (std::size_t i = 0; i < L; ++i) {
      const Eigen::Vector3d p_C = R_CW * (out.landmarks_w[i] - c_W);
      seen[i] = 0;
      if (!(p_C.z() >= config.min_depth_m) || std::abs(p_C.x()) > x_max * p_C.z() ||
          std::abs(p_C.y()) > y_max * p_C.z())
        continue;
      const std::optional<Eigen::Vector2d> uv = camera.project(p_C);
      if (!uv) continue;
      proj[i] = *uv;
      seen[i] = 1;
      visible.push_back(i);
    }
    // Tracks that go on, then new ones where the mask leaves room.
    next.clear();
    grid.clear();
    for (const Track& t : active) {
      if (seen[t.landmark] && t.length < t.limit) {
        next.push_back(t);
        grid.add(proj[t.landmark]);
      } else {
        tracked[t.landmark] = 0;
      }
    }
    if (next.size() < target) {
      candidates.clear();
      for (const std::size_t i : visible)
        if (!tracked[i]) candidates.push_back(i);
      rng.shuffle(candidates);
      for (const std::size_t i : candidates) {
        if (next.size() >= target) break;
        if (!grid.free_at(proj[i])) continue;
        // The id is given with the first observation written (below), so
        // that ids are 0, 1, 2, ... without holes.
        const int limit = limit_lo + int(rng.below(std::size_t(config.max_track_length - limit_lo + 1)));
        next.push_back(Track{i, 0, 0, limit});
        tracked[i] = 1;
        grid.add(proj[i]);
      }
    }
    // Observations.
    TrackFrame frame{t_ns[k], {}};
    std::vector<ObservationTruth> truth;
    frame.features.reserve(next.size());
    truth.reserve(next.size());
    active.clear();
    for (Track t : next) {
      const Eigen::Vector2d& uv_true = proj[t.landmark];
      Eigen::Vector2d source = uv_true;
      bool wrong = false;
      if (config.outlier_fraction > 0 && rng.uniform() < config.outlier_fraction) {
        for (int attempt = 0; attempt < 10 && !wrong; ++attempt) {
          const std::size_t j = visible[rng.below(visible.size())];
          if (j != t.landmark && (proj[j] - uv_true).norm() >= min_err) {
            source = proj[j];
            wrong = true;
          }
        }
        for (int attempt = 0; attempt < 100 && !wrong; ++attempt) {
          const Eigen::Vector2d r(rng.uniform(-0.5, camera.width - 0.5), rng.uniform(-0.5, camera.height - 0.5));
          if ((r - uv_true).norm() >= min_err) {
            source = r;
            wrong = true;
          }
        }
      }
      const double nu = rng.normal(sigma), nv = rng.normal(sigma);
      const Eigen::Vector2d uv = source + Eigen::Vector2d(nu, nv);
      if (!camera.in_image(uv)) {
        tracked[t.landmark] = 0;
        continue;
      }
      if (t.length == 0) {
        if (config.recurring_ids) {
          t.id = std::uint64_t(t.landmark);
        } else {
          t.id = std::uint64_t(out.landmark_of_id.size());
          out.landmark_of_id.push_back(t.landmark);
        }
      }
      ++t.length;
      frame.features.push_back(FeatureObservation{t.id, uv});
      truth.push_back(ObservationTruth{t.landmark, uv_true, wrong});
      out.wrong_associations += wrong ? 1 : 0;
      active.push_back(t);
    }
    out.observations += frame.features.size();
    if (frame.features.size() < target) ++out.frames_below_target;
    out.tracks.push_back(std::move(frame));
    out.truth.push_back(std::move(truth));
  }
  return out;
}

/// Simulates tracks along a ground truth: frames at config.rate_hz from its
/// first stamp to its last, each pose interpolated between the two states
/// around it (interpolate_pose: linear translation, slerp rotation; a frame
/// on a state's stamp takes that pose).
/// @throws posefuse::invalid_argument for a frame between two states more
///         than config.max_pose_gap_s apart (naming both stamps), and as the
///         overload above
[[nodiscard]] inline SimulatedTracks simulate_feature_tracks(const EurocGroundTruth& gt,
                                                             const PinholeRadtan& camera,
                                                             const TrackSimConfig& config) {
  config.validate();
  if (gt.size() == 0) throw invalid_argument("simulate_feature_tracks: empty ground truth");
  const std::vector<std::int64_t> t = frame_stamps(gt.t_ns.front(), gt.t_ns.back(), config.rate_hz);
  const auto max_gap_ns = std::int64_t(std::llround(config.max_pose_gap_s * 1e9));
  std::vector<Eigen::Isometry3d> poses;
  poses.reserve(t.size());
  std::size_t j = 0;  // gt.t_ns[j] <= t < gt.t_ns[j + 1]
  for (const std::int64_t tk : t) {
    while (j + 1 < gt.size() && gt.t_ns[j + 1] <= tk) ++j;
    if (gt.t_ns[j] == tk) {
      poses.push_back(gt.trajectory.poses[j]);
      continue;
    }
    const std::int64_t ta = gt.t_ns[j], tb = gt.t_ns[j + 1];
    if (tb - ta > max_gap_ns)
      throw invalid_argument("the ground truth has a gap of " + posefuse::detail::message_number(double(tb - ta) * 1e-9) +
                             " s between " + std::to_string(ta) + " and " + std::to_string(tb) +
                             " ns, longer than the " + posefuse::detail::message_number(config.max_pose_gap_s) +
                             " s a frame may be interpolated across");
    const double f = double(tk - ta) / double(tb - ta);
    poses.push_back(interpolate_pose(gt.trajectory.poses[j], gt.trajectory.poses[j + 1], f));
  }
  return simulate_feature_tracks(t, poses, camera, config);
}

/// The built-in synthetic flight: sim/imu.hpp's analytic trajectory with
/// its default ImuSimConfig (a smooth 3-D Lissajous-like motion, z up,
/// speeds up to about 2.5 m/s, yaw swinging ±1.2 rad), so that an IMU
/// simulated with the same config (simulate_imu) moves exactly as the
/// camera does.
[[nodiscard]] inline ImuSimConfig synthetic_flight() { return ImuSimConfig{}; }

/// A camera for the synthetic flight: EuRoC's cam0 intrinsics and
/// distortion (752 x 480, 20 Hz) looking along the body's x axis
/// (camera z = body x, camera x = -body y, camera y = -body z), 5 cm ahead
/// of the body origin.
[[nodiscard]] inline PinholeRadtan synthetic_camera() {
  PinholeRadtan c;
  c.fu = 458.654;
  c.fv = 457.296;
  c.cu = 367.215;
  c.cv = 248.375;
  c.distortion = {-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05};
  c.width = 752;
  c.height = 480;
  c.rate_hz = 20;
  Eigen::Matrix3d R_BC;
  R_BC << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  c.T_BS = Eigen::Isometry3d::Identity();
  c.T_BS.linear() = R_BC;
  c.T_BS.translation() = Eigen::Vector3d(0.05, 0, 0);
  return c;
}

/// The flight's ground truth at `rate_hz` for `duration_s` from
/// flight.start_t_ns: poses, velocity and (constant, flight.initial_bias)
/// biases, as a EuRoC ground truth with 17 columns.
/// @throws posefuse::invalid_argument for a non-positive rate or duration
[[nodiscard]] inline EurocGroundTruth synthetic_groundtruth(const ImuSimConfig& flight, double duration_s,
                                                            double rate_hz) {
  if (!(duration_s > 0 && std::isfinite(duration_s)))
    throw invalid_argument("synthetic_groundtruth: duration must be finite and > 0");
  const std::vector<std::int64_t> t = frame_stamps(
      flight.start_t_ns, flight.start_t_ns + std::llround(duration_s * 1e9), rate_hz);
  const ImuTrajectory traj(flight);
  EurocGroundTruth gt;
  gt.velocity.emplace();
  gt.gyro_bias.emplace();
  gt.accel_bias.emplace();
  for (const std::int64_t tk : t) {
    const double s = double(tk - flight.start_t_ns) * 1e-9;
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = traj.rotation(s).matrix();
    T.translation() = traj.position(s);
    gt.t_ns.push_back(tk);
    gt.trajectory.push_back(seconds_from_ns(tk), T);
    gt.velocity->push_back(traj.velocity(s));
    gt.gyro_bias->push_back(flight.initial_bias.gyro);
    gt.accel_bias->push_back(flight.initial_bias.accel);
  }
  return gt;
}

/// Simulates tracks along the synthetic flight for `duration_s`, poses
/// taken exactly from its analytic trajectory at the frame stamps
/// (flight.start_t_ns + k / rate).
/// @throws posefuse::invalid_argument as simulate_feature_tracks
[[nodiscard]] inline SimulatedTracks simulate_feature_tracks(const ImuSimConfig& flight, double duration_s,
                                                             const PinholeRadtan& camera,
                                                             const TrackSimConfig& config) {
  config.validate();
  const EurocGroundTruth gt = synthetic_groundtruth(flight, duration_s, config.rate_hz);
  return simulate_feature_tracks(gt.t_ns, gt.trajectory.poses, camera, config);
}

}  // namespace posefuse::sim
