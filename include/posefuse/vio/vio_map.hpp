#pragma once
/// @file
/// A visual-inertial map: the keyframes of the loop-closure pose graph
/// (vio/loop_closure.hpp) with what relocalisation needs (their odometry
/// pose, extrinsic, features with ids, normalised observations and world
/// points), the graph's poses and its edges; saved to and loaded from a
/// documented text file.
///
/// **File format** (text, one record per line, fields separated by spaces or
/// tabs, blank lines and lines starting with '#' skipped). The first record
/// is the header `posefuse_vio_map 1`; then, in this order of dependence
/// (a record names only keyframes defined above it):
///
///     keyframe ID SEQ T_NS  OX OY OZ OQW OQX OQY OQZ  EX EY EZ EQW EQX EQY EQZ  X Y Z YAW PITCH ROLL  FIXED
///     feature KF_ID FEATURE_ID MX MY [PX PY PZ]
///     edge KIND FROM TO DX DY DZ DYAW  I11 I12 I13 I14 I22 I23 I24 I33 I34 I44  LOSS SCALE
///
/// * `keyframe`: node id (int64, unique), sequence (a session's keyframes,
///   int ≥ 0), image stamp (ns, int64); the body pose from the odometry
///   \f$ T_{w,b} \f$ in that session's odometry frame (position m, unit
///   quaternion w x y z), the camera–body extrinsic \f$ T_{b,c} \f$ (same
///   layout), the keyframe's pose in the map's frame after loop closure
///   (graph/edge_error_4dof.hpp's Pose4Dof: position m, yaw, pitch, roll rad),
///   and 1 when the node is held fixed, else 0;
/// * `feature`: a feature the keyframe saw: its id (uint64, unique within
///   the keyframe), normalised coordinates (x/z, y/z) and, when the odometry
///   triangulated it, its point in the keyframe's odometry frame (m);
/// * `edge`: `sequential` (odometry between consecutive keyframes) or
///   `loop`; the 4-DoF measurement (TO's position in FROM's frame, m; yaw
///   difference, rad), the upper triangle of its 4x4 information (order
///   x, y, z, yaw; symmetric positive semi-definite) row by row, and its
///   robust loss `none`, `huber` or `cauchy` with its scale (> 0).
///
/// Numbers are written with 17 significant digits, so a map saved and
/// loaded again is the same map, bit for bit (its quaternions are kept as
/// written: nothing is re-normalised on loading). Loading checks every
/// record and throws posefuse::io_error `file:line: reason` for: a missing or
/// wrong header, an unknown record, a wrong number of fields, a number that
/// does not parse or is not finite, a quaternion whose norm is not 1 within
/// 1e-9, a repeated keyframe id, a feature or edge naming a keyframe not
/// defined above, a repeated feature id within a keyframe, an unknown edge
/// kind or loss, an edge from a keyframe to itself, an information matrix
/// that is not positive semi-definite, a loss scale that is not > 0, and a
/// file without keyframes.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>
#include <string_view>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include <posefuse/core/definiteness.hpp>
#include <posefuse/core/error.hpp>
#include <posefuse/graph/edge_error_4dof.hpp>
#include <posefuse/io/detail/line_reader.hpp>
#include <posefuse/io/detail/text.hpp>
#include <posefuse/vio/keyframe_record.hpp>

namespace posefuse {

/// A rigid pose as stored in a map: position and unit quaternion, kept as
/// written (see the file comment).
struct MapPose {
  Eigen::Vector3d p = Eigen::Vector3d::Zero();                 ///< position (m)
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity();       ///< rotation (unit)
  /// As an SE3d (the quaternion is normalised by SO3).
  [[nodiscard]] SE3d se3() const { return SE3d(p, SO3d(q)); }
  /// From an SE3d, exactly.
  [[nodiscard]] static MapPose of(const SE3d& T) { return MapPose{T.translation(), T.so3().quaternion()}; }
};

/// One keyframe of a map (see the file comment).
struct MapKeyframe {
  std::int64_t id = 0;                    ///< node id, unique in the map
  int sequence = 0;                       ///< the session it came from
  std::int64_t t_ns = 0;                  ///< image stamp (ns)
  MapPose T_w_b;                          ///< odometry body pose (that session's odometry frame)
  MapPose T_b_c;                          ///< camera pose in the body frame
  Pose4Dof pose;                          ///< pose in the map's frame (after loop closure)
  bool fixed = false;                     ///< held fixed in the pose graph
  std::vector<KeyframeFeature> features;  ///< ids unique; points in the odometry frame
};

/// Kind of a map edge.
enum class MapEdgeKind { kSequential, kLoop };

/// One edge of a map: its kind and the 4-DoF measurement.
struct MapEdge {
  MapEdgeKind kind = MapEdgeKind::kSequential;  ///< odometry or loop
  Edge4Dof edge;                                ///< between keyframe ids
};

/// A map: keyframes and edges (see the file comment).
struct VioMap {
  std::vector<MapKeyframe> keyframes;  ///< in the order they were added
  std::vector<MapEdge> edges;          ///< in the order they were added
};

/// The header line of a map file.
inline constexpr std::string_view kVioMapHeader = "posefuse_vio_map 1";

namespace detail::vio_map_io {

inline std::string num(double x) {
  char buf[40];
  std::snprintf(buf, sizeof(buf), "%.17g", x);
  return buf;
}

inline void pose(std::string& s, const MapPose& T) {
  for (double x : {T.p.x(), T.p.y(), T.p.z(), T.q.w(), T.q.x(), T.q.y(), T.q.z()}) s += ' ' + num(x);
}

inline const char* loss_name(RobustLoss l) {
  return l == RobustLoss::kHuber ? "huber" : l == RobustLoss::kCauchy ? "cauchy" : "none";
}

template <class Int>
[[nodiscard]] Int parse_int(std::string_view t, const std::filesystem::path& file, std::size_t line,
                            const char* what) {
  Int v{};
  const auto [ptr, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
  if (ec != std::errc{} || ptr != t.data() + t.size() || t.empty())
    throw io_error(file, line, "cannot parse '" + std::string(t) + "' as " + what);
  return v;
}

inline double parse_real(std::string_view t, const std::filesystem::path& file, std::size_t line,
                         std::size_t column) {
  return detail::traj_io::parse_number(t, file, line, column);  // finite, or io_error naming the column
}

}  // namespace detail::vio_map_io

/// Writes a map (see the file comment).
/// @throws posefuse::io_error when the file cannot be written
template <class Lazy = void>
void save_vio_map(const std::filesystem::path& file, const VioMap& map) {
  using namespace detail::vio_map_io;
  std::ofstream out = detail::traj_io::open_output(file);
  out << kVioMapHeader << '\n';
  out << "# keyframe ID SEQ T_NS  odometry T_w_b: X Y Z QW QX QY QZ  extrinsic T_b_c: X Y Z QW QX QY QZ"
         "  map pose: X Y Z YAW PITCH ROLL  FIXED\n";
  out << "# feature KF_ID FEATURE_ID MX MY [PX PY PZ]\n";
  out << "# edge sequential|loop FROM TO DX DY DZ DYAW  information upper triangle (10)  none|huber|cauchy SCALE\n";
  std::string s;
  for (const MapKeyframe& k : map.keyframes) {
    s = "keyframe " + std::to_string(k.id) + ' ' + std::to_string(k.sequence) + ' ' + std::to_string(k.t_ns);
    pose(s, k.T_w_b);
    pose(s, k.T_b_c);
    for (double x : {k.pose.p.x(), k.pose.p.y(), k.pose.p.z(), k.pose.yaw, k.pose.pitch, k.pose.roll})
      s += ' ' + num(x);
    s += k.fixed ? " 1\n" : " 0\n";
    out << s;
    for (const KeyframeFeature& f : k.features) {
      s = "feature " + std::to_string(k.id) + ' ' + std::to_string(f.id) + ' ' + num(f.m.x()) + ' ' + num(f.m.y());
      if (f.has_point) s += ' ' + num(f.p_w.x()) + ' ' + num(f.p_w.y()) + ' ' + num(f.p_w.z());
      s += '\n';
      out << s;
    }
  }
  for (const MapEdge& e : map.edges) {
    s = std::string("edge ") + (e.kind == MapEdgeKind::kLoop ? "loop " : "sequential ") +
        std::to_string(e.edge.from) + ' ' + std::to_string(e.edge.to);
    for (double x : {e.edge.dp.x(), e.edge.dp.y(), e.edge.dp.z(), e.edge.dyaw}) s += ' ' + num(x);
    for (int r = 0; r < 4; ++r)
      for (int c = r; c < 4; ++c) s += ' ' + num(e.edge.information(r, c));
    s += std::string(" ") + loss_name(e.edge.loss.type) + ' ' + num(e.edge.loss.scale) + '\n';
    out << s;
  }
  detail::traj_io::finish_output(out, file);
}

/// Reads a map (see the file comment).
/// @throws posefuse::io_error (file:line) for each malformation the file
///         comment lists; (file) when it cannot be read or has no keyframe
template <class Lazy = void>
[[nodiscard]] VioMap load_vio_map(const std::filesystem::path& file) {
  using namespace detail::vio_map_io;
  detail::LineReader reader(file);
  VioMap map;
  std::unordered_map<std::int64_t, std::size_t> index;               // keyframe id -> position
  std::vector<std::unordered_set<std::uint64_t>> feature_ids;        // per keyframe
  std::string line;
  bool header = false;
  const auto keyframe_of = [&](std::string_view t, std::size_t n, const char* role) -> std::size_t {
    const auto id = parse_int<std::int64_t>(t, file, n, "a keyframe id (int64)");
    const auto it = index.find(id);
    if (it == index.end())
      throw io_error(file, n, std::string(role) + " keyframe " + std::to_string(id) + " is not defined above");
    return it->second;
  };
  const auto read_pose = [&](const std::vector<std::string_view>& f, std::size_t at, std::size_t n) {
    MapPose T;
    T.p = Eigen::Vector3d(parse_real(f[at], file, n, at + 1), parse_real(f[at + 1], file, n, at + 2),
                          parse_real(f[at + 2], file, n, at + 3));
    T.q = Eigen::Quaterniond(parse_real(f[at + 3], file, n, at + 4), parse_real(f[at + 4], file, n, at + 5),
                             parse_real(f[at + 5], file, n, at + 6), parse_real(f[at + 6], file, n, at + 7));
    if (!(std::abs(T.q.norm() - 1.0) <= 1e-9))
      throw io_error(file, n,
                     "the quaternion in columns " + std::to_string(at + 4) + "-" + std::to_string(at + 7) +
                         " has norm " + num(T.q.norm()) + ", not 1");
    return T;
  };
  while (reader.next(line)) {
    if (detail::traj_io::is_blank_or_comment(line)) continue;
    const std::size_t n = reader.line_no();
    const std::vector<std::string_view> f = detail::traj_io::split_whitespace(line);
    if (!header) {
      if (f.size() != 2 || f[0] != "posefuse_vio_map")
        throw io_error(file, n, "expected the header '" + std::string(kVioMapHeader) + "'");
      if (f[1] != "1") throw io_error(file, n, "unsupported map version '" + std::string(f[1]) + "' (expected 1)");
      header = true;
      continue;
    }
    const auto expect = [&](bool ok, const char* layout) {
      if (!ok)
        throw io_error(file, n,
                       std::string(f[0] == "edge" ? "an " : "a ") + std::string(f[0]) + " record has " +
                           std::string(layout) + " fields, found " +
                           std::to_string(f.size()));
    };
    if (f[0] == "keyframe") {
      expect(f.size() == 25, "25");
      MapKeyframe k;
      k.id = parse_int<std::int64_t>(f[1], file, n, "a keyframe id (int64)");
      k.sequence = parse_int<int>(f[2], file, n, "a sequence number (int >= 0)");
      if (k.sequence < 0) throw io_error(file, n, "the sequence number " + std::string(f[2]) + " is negative");
      k.t_ns = parse_int<std::int64_t>(f[3], file, n, "a timestamp in ns (int64)");
      k.T_w_b = read_pose(f, 4, n);
      k.T_b_c = read_pose(f, 11, n);
      k.pose.p = Eigen::Vector3d(parse_real(f[18], file, n, 19), parse_real(f[19], file, n, 20),
                                 parse_real(f[20], file, n, 21));
      k.pose.yaw = parse_real(f[21], file, n, 22);
      k.pose.pitch = parse_real(f[22], file, n, 23);
      k.pose.roll = parse_real(f[23], file, n, 24);
      if (f[24] != "0" && f[24] != "1")
        throw io_error(file, n, "the fixed flag is '" + std::string(f[24]) + "', expected 0 or 1");
      k.fixed = f[24] == "1";
      if (!index.emplace(k.id, map.keyframes.size()).second)
        throw io_error(file, n, "keyframe id " + std::to_string(k.id) + " is defined twice");
      map.keyframes.push_back(std::move(k));
      feature_ids.emplace_back();
    } else if (f[0] == "feature") {
      expect(f.size() == 5 || f.size() == 8, "5 or 8");
      const std::size_t k = keyframe_of(f[1], n, "its");
      KeyframeFeature x;
      x.id = parse_int<std::uint64_t>(f[2], file, n, "a feature id (uint64)");
      x.m = Eigen::Vector2d(parse_real(f[3], file, n, 4), parse_real(f[4], file, n, 5));
      if (f.size() == 8) {
        x.has_point = true;
        x.p_w = Eigen::Vector3d(parse_real(f[5], file, n, 6), parse_real(f[6], file, n, 7),
                                parse_real(f[7], file, n, 8));
      }
      if (!feature_ids[k].insert(x.id).second)
        throw io_error(file, n,
                       "feature " + std::to_string(x.id) + " appears twice in keyframe " +
                           std::to_string(map.keyframes[k].id));
      map.keyframes[k].features.push_back(x);
    } else if (f[0] == "edge") {
      expect(f.size() == 20, "20");
      MapEdge e;
      if (f[1] == "sequential") e.kind = MapEdgeKind::kSequential;
      else if (f[1] == "loop") e.kind = MapEdgeKind::kLoop;
      else throw io_error(file, n, "unknown edge kind '" + std::string(f[1]) + "' (sequential or loop)");
      e.edge.from = map.keyframes[keyframe_of(f[2], n, "the edge's first")].id;
      e.edge.to = map.keyframes[keyframe_of(f[3], n, "the edge's second")].id;
      if (e.edge.from == e.edge.to)
        throw io_error(file, n, "the edge joins keyframe " + std::to_string(e.edge.from) + " to itself");
      e.edge.dp = Eigen::Vector3d(parse_real(f[4], file, n, 5), parse_real(f[5], file, n, 6),
                                  parse_real(f[6], file, n, 7));
      e.edge.dyaw = parse_real(f[7], file, n, 8);
      std::size_t c = 8;
      for (int r = 0; r < 4; ++r)
        for (int q = r; q < 4; ++q, ++c) {
          e.edge.information(r, q) = parse_real(f[c], file, n, c + 1);
          e.edge.information(q, r) = e.edge.information(r, q);
        }
      if (!is_positive_semidefinite(e.edge.information))
        throw io_error(file, n, "the information matrix is not positive semi-definite");
      if (f[18] == "none") e.edge.loss.type = RobustLoss::kNone;
      else if (f[18] == "huber") e.edge.loss.type = RobustLoss::kHuber;
      else if (f[18] == "cauchy") e.edge.loss.type = RobustLoss::kCauchy;
      else throw io_error(file, n, "unknown loss '" + std::string(f[18]) + "' (none, huber or cauchy)");
      e.edge.loss.scale = parse_real(f[19], file, n, 20);
      if (!(e.edge.loss.scale > 0)) throw io_error(file, n, "the loss scale must be > 0");
      map.edges.push_back(e);
    } else {
      throw io_error(file, n, "unknown record '" + std::string(f[0]) + "' (keyframe, feature or edge)");
    }
  }
  if (!header) throw io_error(file, "empty file: expected the header '" + std::string(kVioMapHeader) + "'");
  if (map.keyframes.empty()) throw io_error(file, "the map has no keyframe");
  return map;
}

}  // namespace posefuse
