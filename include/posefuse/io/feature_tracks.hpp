#pragma once
/// @file
/// Feature tracks: the output of a visual front end (a feature tracker) as
/// one csv per camera, the input of the visual-inertial estimator
/// (vio/). Any front end can write it: all it needs is the pixel of each
/// tracked feature and an id that names one landmark for as long as it is
/// tracked.
///
///     t_ns,feature_id,u,v
///     1403715273262142976,0,102.5,33.25
///     1403715273262142976,1,640.125,301
///     1403715273312143104,0,104.75,33.5
///
/// * `t_ns`: the image's stamp, a decimal integer (ns, int64); all rows of
///   one image share it and are consecutive; stamps never decrease;
/// * `feature_id`: a decimal integer (uint64), unique within an image; the
///   same id in later images is the same landmark;
/// * `u, v`: the pixel in the **raw (distorted) image**, pixel centres at
///   integer coordinates (vio/camera.hpp), finite.
///
/// **Strictness.** Blank lines and lines starting with '#' are skipped; the
/// first other line may be the header `t_ns,feature_id,u,v`. Every other line
/// has exactly 4 comma-separated fields (spaces around them allowed), or it
/// is a posefuse::io_error `file:line: reason`; as are a stamp earlier than
/// the previous row's (naming both lines), an id repeated within one image
/// (naming both lines), a non-finite or unparsable number, and — when the
/// image size is given — a pixel outside the image
/// \f$ [-0.5, w - 0.5] \times [-0.5, h - 0.5] \f$. A file without rows is an
/// error too. Sub-pixel trackers and undistort/redistort round trips give
/// pixels a little outside the image: with FeatureTrackReadOptions::
/// drop_margin_px > 0, a pixel outside the image by at most that margin is
/// dropped (counted by read_feature_tracks_counted) instead of refused; one
/// farther out is still refused (a wrong image size, a wrong file).

#include <Eigen/Core>
#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <system_error>
#include <unordered_map>
#include <vector>

#include <posefuse/core/error.hpp>
#include <posefuse/io/detail/csv.hpp>
#include <posefuse/io/detail/line_reader.hpp>
#include <posefuse/io/detail/message_number.hpp>
#include <posefuse/io/detail/text.hpp>
#include <posefuse/io/euroc.hpp>

namespace posefuse {

/// One feature seen in one image.
struct FeatureObservation {
  std::uint64_t id = 0;                         ///< landmark id, unique over time
  Eigen::Vector2d uv = Eigen::Vector2d::Zero();  ///< pixel in the raw image (px)
};

/// The features of one image.
struct TrackFrame {
  std::int64_t t_ns = 0;                         ///< the image's stamp (ns)
  std::vector<FeatureObservation> features;      ///< ids unique within the frame
};

/// A camera's feature tracks: frames with strictly increasing `t_ns`.
using FeatureTracks = std::vector<TrackFrame>;

/// What read_feature_tracks checks beyond the format.
struct FeatureTrackReadOptions {
  /// Image size (px); pixels outside the image are refused when both are > 0.
  int image_width = 0;
  int image_height = 0;  ///< see image_width
  /// Pixels outside the image by at most this much (px, per axis) are
  /// dropped rather than refused; 0: every pixel outside is refused.
  double drop_margin_px = 0.0;
};

/// Feature tracks and the observations the reader dropped.
struct FeatureTrackRead {
  FeatureTracks tracks;           ///< the frames (see read_feature_tracks)
  std::size_t dropped = 0;        ///< observations outside the image within the margin
  std::size_t first_dropped_line = 0;  ///< line of the first of them (0: none)
  double worst_outside_px = 0.0;  ///< how far outside the image the farthest was (px)
};

/// The header line the writer writes and the reader accepts.
inline constexpr std::string_view kFeatureTrackHeader = "t_ns,feature_id,u,v";

namespace detail::tracks_io {

/// Parses an unsigned 64-bit decimal feature id.
template <class Lazy = void>
[[nodiscard]] std::uint64_t parse_id(std::string_view token, const std::filesystem::path& file,
                                     std::size_t line) {
  std::uint64_t v = 0;
  const char* const end = token.data() + token.size();
  const auto [ptr, ec] = std::from_chars(token.data(), end, v);
  if (ec != std::errc{} || ptr != end || token.empty())
    throw io_error(file, line,
                   "cannot parse '" + std::string(token) +
                       "' in column 2 as a feature id (a non-negative integer below 2^64)");
  return v;
}

}  // namespace detail::tracks_io

/// Reads a feature-track csv (see the file comment).
/// @param[in] file the csv
/// @param[in] options the image size to check pixels against (optional)
/// @return the frames in file order, stamps strictly increasing, each with
///         its features in file order (less the dropped ones), and the
///         count of observations dropped within options.drop_margin_px
/// @throws posefuse::io_error (file:line) for every violation listed in the
///         file comment; (file) when it cannot be read or has no rows
/// @throws posefuse::invalid_argument for a negative or non-finite margin
template <class Lazy = void>
[[nodiscard]] FeatureTrackRead read_feature_tracks_counted(const std::filesystem::path& file,
                                                           const FeatureTrackReadOptions& options = {}) {
  if (!(options.drop_margin_px >= 0.0 && std::isfinite(options.drop_margin_px)))
    throw invalid_argument("read_feature_tracks: drop_margin_px must be finite and >= 0");
  detail::LineReader reader(file);
  FeatureTrackRead result;
  FeatureTracks& out = result.tracks;
  std::unordered_map<std::uint64_t, std::size_t> frame_ids;  // id -> line, current frame
  const bool check_image = options.image_width > 0 && options.image_height > 0;
  const double u_max = options.image_width - 0.5, v_max = options.image_height - 0.5;
  std::string line;
  std::size_t previous_line = 0;
  bool first = true;
  while (reader.next(line)) {
    if (detail::traj_io::is_blank_or_comment(line)) continue;
    const std::size_t n = reader.line_no();
    const std::vector<std::string_view> f = detail::split_csv(line);
    if (first) {
      first = false;
      if (f.size() == 4 && f[0] == "t_ns" && f[1] == "feature_id" && f[2] == "u" && f[3] == "v")
        continue;
    }
    if (f.size() != 4)
      throw io_error(file, n,
                     "expected 4 comma-separated fields (t_ns, feature_id, u, v), found " +
                         std::to_string(f.size()));
    const std::int64_t t = detail::parse_stamp(f[0], file, n);
    FeatureObservation o;
    o.id = detail::tracks_io::parse_id(f[1], file, n);
    o.uv = Eigen::Vector2d(detail::traj_io::parse_number(f[2], file, n, 3),
                           detail::traj_io::parse_number(f[3], file, n, 4));
    bool drop = false;
    if (check_image && !(o.uv.x() >= -0.5 && o.uv.x() <= u_max && o.uv.y() >= -0.5 && o.uv.y() <= v_max)) {
      const double outside = std::max({-0.5 - o.uv.x(), o.uv.x() - u_max, -0.5 - o.uv.y(), o.uv.y() - v_max});
      if (!(outside <= options.drop_margin_px))
        throw io_error(file, n,
                       "pixel (" + detail::message_number(o.uv.x()) + ", " + detail::message_number(o.uv.y()) +
                           ") is outside the " + std::to_string(options.image_width) + "x" +
                           std::to_string(options.image_height) + " image ([-0.5, " +
                           detail::message_number(u_max) + "] x [-0.5, " + detail::message_number(v_max) + "]" +
                           (options.drop_margin_px > 0
                                ? " by " + detail::message_number(outside) + " px, more than the " +
                                      detail::message_number(options.drop_margin_px) + " px margin"
                                : std::string()) +
                           ")");
      drop = true;
      if (result.dropped++ == 0) result.first_dropped_line = n;
      result.worst_outside_px = std::max(result.worst_outside_px, outside);
    }
    if (out.empty() || t > out.back().t_ns) {
      out.push_back(TrackFrame{t, {}});
      frame_ids.clear();
    } else if (t < out.back().t_ns) {
      detail::traj_io::throw_stamp_out_of_order(t, out.back().t_ns, previous_line, file, n,
                                                /*offer_policies=*/false);
    }
    const auto [it, inserted] = frame_ids.emplace(o.id, n);
    if (!inserted)
      throw io_error(file, n,
                     "feature id " + std::to_string(o.id) + " repeats within the image at " +
                         std::to_string(t) + " ns (line " + std::to_string(it->second) + ")");
    if (!drop) out.back().features.push_back(o);
    previous_line = n;
  }
  if (out.empty()) throw io_error(file, "no feature observations (the file has no data rows)");
  return result;
}

/// Reads a feature-track csv (see the file comment); read_feature_tracks_counted
/// without the count of dropped observations.
/// @throws posefuse::io_error as read_feature_tracks_counted
template <class Lazy = void>
[[nodiscard]] FeatureTracks read_feature_tracks(const std::filesystem::path& file,
                                                const FeatureTrackReadOptions& options = {}) {
  return read_feature_tracks_counted(file, options).tracks;
}

/// Writes feature tracks as csv with the header line (see the file comment);
/// numbers are written in their shortest exact form, so the file reads back
/// bit for bit. Frames without features write no row (the reader will not
/// see them).
/// @throws posefuse::invalid_argument for stamps that do not increase, a
///         repeated id within a frame or a non-finite pixel (nothing is written)
/// @throws posefuse::io_error when the file cannot be written
template <class Lazy = void>
void write_feature_tracks(const std::filesystem::path& file, const FeatureTracks& tracks) {
  std::unordered_map<std::uint64_t, int> ids;
  for (std::size_t k = 0; k < tracks.size(); ++k) {
    if (k > 0 && !(tracks[k].t_ns > tracks[k - 1].t_ns))
      throw invalid_argument("write_feature_tracks: frame " + std::to_string(k) + " stamp " +
                             std::to_string(tracks[k].t_ns) + " does not follow " +
                             std::to_string(tracks[k - 1].t_ns));
    ids.clear();
    for (const FeatureObservation& o : tracks[k].features) {
      if (!o.uv.allFinite())
        throw invalid_argument("write_feature_tracks: non-finite pixel of feature " +
                               std::to_string(o.id) + " at " + std::to_string(tracks[k].t_ns));
      if (!ids.emplace(o.id, 0).second)
        throw invalid_argument("write_feature_tracks: feature id " + std::to_string(o.id) +
                               " twice at " + std::to_string(tracks[k].t_ns));
    }
  }
  std::ofstream out = detail::traj_io::open_output(file);
  out << kFeatureTrackHeader << '\n';
  std::string row;
  for (const TrackFrame& fr : tracks) {
    const std::string stamp = std::to_string(fr.t_ns);
    for (const FeatureObservation& o : fr.features) {
      row = stamp;
      row += ',';
      row += std::to_string(o.id);
      row += ',';
      row += detail::traj_io::format_number(o.uv.x());
      row += ',';
      row += detail::traj_io::format_number(o.uv.y());
      row += '\n';
      out << row;
    }
  }
  detail::traj_io::finish_output(out, file);
}

}  // namespace posefuse
