#pragma once
/// @file
/// g2o's 3-D pose-graph files (`VERTEX_SE3:QUAT`, `EDGE_SE3:QUAT`, `FIX`),
/// read and written, and which of the two g2o formats a file holds.
///
/// **Format** (Kümmerle et al., "g2o: A General Framework for Graph
/// Optimization", ICRA 2011; its `types_slam3d`):
/// ```
/// VERTEX_SE3:QUAT id x y z qx qy qz qw
/// EDGE_SE3:QUAT i j x y z qx qy qz qw I11 I12 .. I16 I22 .. I26 .. I66
/// FIX id [id ...]
/// ```
/// A vertex is a pose in the world frame, an edge the pose of j in i's
/// frame followed by the upper triangle (21 numbers) of its 6x6 information
/// matrix row by row in the order (x, y, z, qx, qy, qz). g2o's error is
/// \f$ [t; q_{xyz}] \f$ of \f$ Z^{-1} X_i^{-1} X_j \f$ (graph/edge_error_se3.hpp).
///
/// Quaternions must be finite with a norm within 1e-3 of 1 (files print
/// about six digits); they are normalised on reading. A zero quaternion or
/// one farther from unit norm is refused, as is an information matrix that
/// is not positive semi-definite (symmetry holds by construction: only the
/// upper triangle is stored).

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>
#include <unordered_map>
#include <utility>
#include <vector>

#include <posefuse/core/error.hpp>
#include <posefuse/io/detail/line_reader.hpp>
#include <posefuse/io/detail/text.hpp>
#include <posefuse/io/g2o.hpp>

namespace posefuse {

/// A g2o `VERTEX_SE3:QUAT`: a pose in the world frame.
struct G2oVertexSE3 {
  std::int64_t id = 0;                                       ///< node id
  Eigen::Vector3d t = Eigen::Vector3d::Zero();               ///< position (m)
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity();     ///< unit quaternion (body -> world)
  std::size_t line = 0;  ///< 1-based line it was read from (0: not read from a file)
};

/// A g2o `EDGE_SE3:QUAT`: the pose of node `to` in the frame of node `from`.
struct G2oEdgeSE3 {
  std::int64_t from = 0;                                     ///< node i
  std::int64_t to = 0;                                       ///< node j
  Eigen::Vector3d t = Eigen::Vector3d::Zero();               ///< m, in i's frame
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity();     ///< unit quaternion
  Eigen::Matrix<double, 6, 6> information = Eigen::Matrix<double, 6, 6>::Identity();  ///< order x, y, z, qx, qy, qz
  std::size_t line = 0;  ///< 1-based line it was read from (0: not read from a file)
};

/// The content of a g2o 3-D file.
struct G2oGraph3d {
  std::vector<G2oVertexSE3> vertices;  ///< in file order
  std::vector<G2oEdgeSE3> edges;       ///< in file order
  std::vector<std::int64_t> fixed;     ///< ids listed by `FIX` lines
};

namespace detail::g2o_io {

/// The unit quaternion of (qx, qy, qz, qw) read on a line.
/// @throws posefuse::io_error for a zero quaternion or a norm farther than 1e-3 from 1
template <class Lazy = void>
[[nodiscard]] Eigen::Quaterniond unit_quaternion(const double* xyzw, const std::filesystem::path& file,
                                                 std::size_t line) {
  const Eigen::Quaterniond q(xyzw[3], xyzw[0], xyzw[1], xyzw[2]);
  const double n = q.norm();
  if (n == 0.0) throw io_error(file, line, "the quaternion is zero");
  if (!(std::abs(n - 1.0) <= 1e-3))
    throw io_error(file, line,
                   "the quaternion is not unit (norm " + detail::message_number(n) + ", expected 1 within 1e-3)");
  return q.normalized();
}

}  // namespace detail::g2o_io

/// Which g2o format a file holds, from its first vertex or edge line: 2
/// (`VERTEX_SE2` / `EDGE_SE2`), 3 (`VERTEX_SE3:QUAT` / `EDGE_SE3:QUAT`).
/// @throws posefuse::io_error (file:line) when the first such line has any
///         other tag; (file only) when it cannot be read or has no vertex or
///         edge line
template <class Lazy = void>
[[nodiscard]] int g2o_dimension(const std::filesystem::path& file) {
  detail::LineReader reader(file);
  std::string line;
  while (reader.next(line)) {
    if (detail::traj_io::is_blank_or_comment(line)) continue;
    const std::string_view tag = detail::traj_io::split_whitespace(line).front();
    if (tag == "FIX") continue;
    if (tag == "VERTEX_SE2" || tag == "EDGE_SE2") return 2;
    if (tag == "VERTEX_SE3:QUAT" || tag == "EDGE_SE3:QUAT") return 3;
    throw io_error(file, reader.line_no(),
                   "unsupported g2o tag '" + std::string(tag) +
                       "' (VERTEX_SE2 / EDGE_SE2 or VERTEX_SE3:QUAT / EDGE_SE3:QUAT expected)");
  }
  throw io_error(file, "no vertex or edge line");
}

/// Reads a g2o 3-D file (`VERTEX_SE3:QUAT`, `EDGE_SE3:QUAT`, `FIX`; blank and `#` lines skipped).
/// @return vertices, edges and fixed ids in file order (quaternions normalised)
/// @throws posefuse::io_error (file:line) for an unknown tag, a wrong number
///         of fields, an unparsable number or id, a non-finite value, a zero
///         or non-unit quaternion, a vertex id defined twice (naming the
///         first line too), an edge from a vertex to itself, an edge or FIX
///         naming an id no vertex line defines (checked once the whole file
///         is read), or an information matrix that is not positive
///         semi-definite; (file only) when the file cannot be read or has no vertex
template <class Lazy = void>
[[nodiscard]] G2oGraph3d read_g2o_3d(const std::filesystem::path& file) {
  namespace io = detail::g2o_io;
  G2oGraph3d g;
  std::unordered_map<std::int64_t, std::size_t> vertex_line;
  std::vector<std::pair<std::int64_t, std::size_t>> referenced;
  detail::LineReader reader(file);
  std::string line;
  while (reader.next(line)) {
    if (detail::traj_io::is_blank_or_comment(line)) continue;
    const std::size_t n = reader.line_no();
    const std::vector<std::string_view> tok = detail::traj_io::split_whitespace(line);
    const std::string_view tag = tok.front();
    const auto expect = [&](std::size_t count, const char* layout) {
      if (tok.size() != count)
        throw io_error(file, n,
                       std::string(tag) + " expects " + std::to_string(count - 1) + " fields (" + layout +
                           "), found " + std::to_string(tok.size() - 1));
    };
    if (tag == "VERTEX_SE3:QUAT") {
      expect(9, "id x y z qx qy qz qw");
      const std::vector<double> v = io::numbers(tok, 2, 7, file, n);
      const std::int64_t id = io::parse_id(tok[1], file, n, 2);
      if (const auto [it, fresh] = vertex_line.emplace(id, n); !fresh)
        throw io_error(file, n,
                       "duplicate vertex id " + std::to_string(id) + " (first defined on line " +
                           std::to_string(it->second) + ")");
      g.vertices.push_back({id, Eigen::Vector3d(v[0], v[1], v[2]), io::unit_quaternion(v.data() + 3, file, n), n});
    } else if (tag == "EDGE_SE3:QUAT") {
      expect(31, "i j x y z qx qy qz qw and the 21 upper-triangle entries of the information");
      const std::vector<double> v = io::numbers(tok, 3, 28, file, n);
      G2oEdgeSE3 e;
      e.from = io::parse_id(tok[1], file, n, 2);
      e.to = io::parse_id(tok[2], file, n, 3);
      if (e.from == e.to) throw io_error(file, n, "edge from vertex " + std::to_string(e.from) + " to itself");
      referenced.emplace_back(e.from, n);
      referenced.emplace_back(e.to, n);
      e.t = Eigen::Vector3d(v[0], v[1], v[2]);
      e.q = io::unit_quaternion(v.data() + 3, file, n);
      e.information = io::from_upper<6>(v.data() + 7);
      io::check_information(e.information, file, n);
      e.line = n;
      g.edges.push_back(e);
    } else if (tag == "FIX") {
      if (tok.size() < 2) throw io_error(file, n, "FIX expects at least one node id");
      for (std::size_t c = 1; c < tok.size(); ++c) {
        g.fixed.push_back(io::parse_id(tok[c], file, n, c + 1));
        referenced.emplace_back(g.fixed.back(), n);
      }
    } else {
      throw io_error(file, n,
                     "unsupported g2o tag '" + std::string(tag) +
                         "' (this reader takes VERTEX_SE3:QUAT, EDGE_SE3:QUAT and FIX)");
    }
  }
  if (g.vertices.empty()) throw io_error(file, "no VERTEX_SE3:QUAT line");
  for (const auto& [id, n] : referenced)
    if (!vertex_line.count(id))
      throw io_error(file, n, "vertex id " + std::to_string(id) + " is not defined by any VERTEX_SE3:QUAT line");
  return g;
}

/// Writes a g2o 3-D file: vertices, then `FIX` (when any), then edges;
/// numbers as the shortest text that reads back exactly.
/// @throws posefuse::invalid_argument, before the file is created, for a
///         graph without vertices (read_g2o_3d refuses a file with no
///         VERTEX_SE3:QUAT line); posefuse::io_error when the file cannot be written
template <class Lazy = void>
void write_g2o_3d(const std::filesystem::path& file, const G2oGraph3d& g) {
  using detail::traj_io::format_number;
  if (g.vertices.empty())
    throw invalid_argument("write_g2o_3d: the graph has no vertex, and a g2o file needs a VERTEX_SE3:QUAT line (" +
                           file.string() + " not written)");
  std::ofstream out = detail::traj_io::open_output(file);
  const auto pose = [&](const Eigen::Vector3d& t, const Eigen::Quaterniond& q) {
    out << ' ' << format_number(t.x()) << ' ' << format_number(t.y()) << ' ' << format_number(t.z()) << ' '
        << format_number(q.x()) << ' ' << format_number(q.y()) << ' ' << format_number(q.z()) << ' '
        << format_number(q.w());
  };
  for (const G2oVertexSE3& v : g.vertices) {
    out << "VERTEX_SE3:QUAT " << v.id;
    pose(v.t, v.q);
    out << '\n';
  }
  if (!g.fixed.empty()) {
    out << "FIX";
    for (const std::int64_t id : g.fixed) out << ' ' << id;
    out << '\n';
  }
  for (const G2oEdgeSE3& e : g.edges) {
    out << "EDGE_SE3:QUAT " << e.from << ' ' << e.to;
    pose(e.t, e.q);
    detail::g2o_io::write_upper<6>(out, e.information);
    out << '\n';
  }
  detail::traj_io::finish_output(out, file);
}

}  // namespace posefuse
