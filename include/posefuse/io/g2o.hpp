#pragma once
/// @file
/// Pose-graph files: g2o's planar format (`VERTEX_SE2`, `EDGE_SE2`, `FIX`)
/// and posefuse's 4-DoF loop-edge text format.
///
/// **g2o 2-D** (Kümmerle et al., "g2o: A General Framework for Graph
/// Optimization", ICRA 2011; the format of its `types_slam2d`):
/// ```
/// VERTEX_SE2 id x y theta
/// EDGE_SE2 i j dx dy dtheta I11 I12 I13 I22 I23 I33
/// FIX id [id ...]
/// ```
/// An edge is the pose of j in i's frame with the upper triangle of its 3x3
/// information matrix, row by row in the order (x, y, theta). g2o's error
/// is \f$ e = t2v(Z^{-1} X_i^{-1} X_j) \f$ and its χ² \f$ \sum e^\top\Omega e \f$.
///
/// **4-DoF loop edges** (posefuse): one edge a line, 16 numbers,
/// ```
/// i j x y z yaw I11 I12 I13 I14 I22 I23 I24 I33 I34 I44
/// ```
/// the position (m) of node j in node i's frame (roll and pitch of i
/// included), the relative yaw (rad), and the upper triangle of the 4x4
/// information matrix row by row in the order (x, y, z, yaw). Blank lines
/// and lines starting with `#` are ignored.
///
/// Readers report malformed lines as posefuse::io_error "file:line: reason";
/// information matrices must be finite and positive semi-definite.

#include <Eigen/Core>
#include <charconv>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>
#include <system_error>
#include <unordered_map>
#include <utility>
#include <vector>

#include <posefuse/core/error.hpp>
#include <posefuse/core/gaussian.hpp>
#include <posefuse/io/detail/line_reader.hpp>
#include <posefuse/io/detail/text.hpp>

namespace posefuse {

/// A g2o `VERTEX_SE2`: a planar pose (m, m, rad) in the world frame.
struct G2oVertexSE2 {
  std::int64_t id = 0;  ///< node id
  double x = 0.0;       ///< m
  double y = 0.0;       ///< m
  double theta = 0.0;   ///< rad
  std::size_t line = 0;  ///< 1-based line it was read from (0: not read from a file)
};

/// A g2o `EDGE_SE2`: the pose of node `to` in the frame of node `from`.
struct G2oEdgeSE2 {
  std::int64_t from = 0;  ///< node i
  std::int64_t to = 0;    ///< node j
  double dx = 0.0;        ///< m, in i's frame
  double dy = 0.0;        ///< m, in i's frame
  double dtheta = 0.0;    ///< rad
  Eigen::Matrix3d information = Eigen::Matrix3d::Identity();  ///< order x, y, theta
  std::size_t line = 0;  ///< 1-based line it was read from (0: not read from a file)
};

/// The content of a g2o 2-D file.
struct G2oGraph2d {
  std::vector<G2oVertexSE2> vertices;  ///< in file order
  std::vector<G2oEdgeSE2> edges;       ///< in file order
  std::vector<std::int64_t> fixed;     ///< ids listed by `FIX` lines
};

/// A 4-DoF loop edge of posefuse's text format (see the file comment).
struct LoopEdge4DofRecord {
  std::int64_t from = 0;                         ///< node i
  std::int64_t to = 0;                           ///< node j
  Eigen::Vector3d dp = Eigen::Vector3d::Zero();  ///< j's position in i's frame (m)
  double dyaw = 0.0;                             ///< relative yaw (rad)
  Eigen::Matrix4d information = Eigen::Matrix4d::Identity();  ///< order x, y, z, yaw
  std::size_t line = 0;  ///< 1-based line it was read from (0: not read from a file)
};

namespace detail::g2o_io {

/// Parses a whole token as a node id (decimal integer).
template <class Lazy = void>
[[nodiscard]] std::int64_t parse_id(std::string_view token, const std::filesystem::path& file,
                                    std::size_t line, std::size_t column) {
  std::int64_t v = 0;
  const char* end = token.data() + token.size();
  const auto res = std::from_chars(token.data(), end, v);
  if (res.ec != std::errc{} || res.ptr != end)
    throw io_error(file, line,
                   "cannot parse '" + std::string(token) + "' in column " + std::to_string(column) +
                       " as a node id (an integer)");
  return v;
}

/// The symmetric matrix from its upper triangle, row by row.
template <int N>
[[nodiscard]] Eigen::Matrix<double, N, N> from_upper(const double* u) {
  Eigen::Matrix<double, N, N> M;
  int k = 0;
  for (int r = 0; r < N; ++r)
    for (int c = r; c < N; ++c) {
      M(r, c) = u[k];
      M(c, r) = u[k];
      ++k;
    }
  return M;
}

/// Writes the upper triangle row by row.
template <int N>
void write_upper(std::ostream& out, const Eigen::Matrix<double, N, N>& M) {
  for (int r = 0; r < N; ++r)
    for (int c = r; c < N; ++c) out << ' ' << traj_io::format_number(M(r, c));
}

/// Parses the numbers of tokens [first, first + count) (1-based columns).
template <class Lazy = void>
[[nodiscard]] std::vector<double> numbers(const std::vector<std::string_view>& tokens, std::size_t first,
                                          std::size_t count, const std::filesystem::path& file,
                                          std::size_t line) {
  std::vector<double> v(count);
  for (std::size_t c = 0; c < count; ++c)
    v[c] = traj_io::parse_number(tokens[first + c], file, line, first + c + 1);
  return v;
}

template <class M>
void check_information(const M& info, const std::filesystem::path& file, std::size_t line) {
  if (!is_positive_semidefinite(info))
    throw io_error(file, line, "the information matrix is not positive semi-definite");
}

}  // namespace detail::g2o_io

/// Reads a g2o 2-D file (`VERTEX_SE2`, `EDGE_SE2`, `FIX`; blank and `#` lines skipped).
/// @param[in] file path
/// @return vertices, edges and fixed ids in file order
/// @throws posefuse::io_error (file:line) for an unknown tag (the message
///         names it), a wrong number of fields, an unparsable number or id, a
///         non-finite value, a vertex id defined twice (the message names
///         the first line too), an edge from a vertex to itself, an edge or
///         FIX naming an id no VERTEX_SE2 line defines (checked once the
///         whole file is read: vertices may follow edges) or an information
///         matrix that is not positive semi-definite; (file only) when the
///         file cannot be read or has no vertex
template <class Lazy = void>
[[nodiscard]] G2oGraph2d read_g2o_2d(const std::filesystem::path& file) {
  namespace io = detail::g2o_io;
  G2oGraph2d g;
  std::unordered_map<std::int64_t, std::size_t> vertex_line;  // id -> line of its VERTEX_SE2
  std::vector<std::pair<std::int64_t, std::size_t>> referenced;  // (id, line) of edge ends and FIX ids
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
    if (tag == "VERTEX_SE2") {
      expect(5, "id x y theta");
      const std::vector<double> v = io::numbers(tok, 2, 3, file, n);
      const std::int64_t id = io::parse_id(tok[1], file, n, 2);
      if (const auto [it, fresh] = vertex_line.emplace(id, n); !fresh)
        throw io_error(file, n,
                       "duplicate vertex id " + std::to_string(id) + " (first defined on line " +
                           std::to_string(it->second) + ")");
      g.vertices.push_back({id, v[0], v[1], v[2], n});
    } else if (tag == "EDGE_SE2") {
      expect(12, "i j dx dy dtheta I11 I12 I13 I22 I23 I33");
      const std::vector<double> v = io::numbers(tok, 3, 9, file, n);
      G2oEdgeSE2 e;
      e.from = io::parse_id(tok[1], file, n, 2);
      e.to = io::parse_id(tok[2], file, n, 3);
      if (e.from == e.to)
        throw io_error(file, n, "edge from vertex " + std::to_string(e.from) + " to itself");
      referenced.emplace_back(e.from, n);
      referenced.emplace_back(e.to, n);
      e.dx = v[0];
      e.dy = v[1];
      e.dtheta = v[2];
      e.information = io::from_upper<3>(v.data() + 3);
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
                         "' (this reader takes VERTEX_SE2, EDGE_SE2 and FIX)");
    }
  }
  if (g.vertices.empty()) throw io_error(file, "no VERTEX_SE2 line");
  for (const auto& [id, n] : referenced)
    if (!vertex_line.count(id))
      throw io_error(file, n, "vertex id " + std::to_string(id) + " is not defined by any VERTEX_SE2 line");
  return g;
}

/// Writes a g2o 2-D file: vertices, then `FIX` (when any), then edges;
/// numbers as the shortest text that reads back exactly.
/// @throws posefuse::invalid_argument, before the file is created, for a
///         graph without vertices (read_g2o_2d refuses a file with no
///         VERTEX_SE2 line); posefuse::io_error when the file cannot be written
template <class Lazy = void>
void write_g2o_2d(const std::filesystem::path& file, const G2oGraph2d& g) {
  namespace io = detail::g2o_io;
  using detail::traj_io::format_number;
  if (g.vertices.empty())
    throw invalid_argument("write_g2o_2d: the graph has no vertex, and a g2o file needs a VERTEX_SE2 line (" +
                           file.string() + " not written)");
  std::ofstream out = detail::traj_io::open_output(file);
  for (const G2oVertexSE2& v : g.vertices)
    out << "VERTEX_SE2 " << v.id << ' ' << format_number(v.x) << ' ' << format_number(v.y) << ' '
        << format_number(v.theta) << '\n';
  if (!g.fixed.empty()) {
    out << "FIX";
    for (const std::int64_t id : g.fixed) out << ' ' << id;
    out << '\n';
  }
  for (const G2oEdgeSE2& e : g.edges) {
    out << "EDGE_SE2 " << e.from << ' ' << e.to << ' ' << format_number(e.dx) << ' '
        << format_number(e.dy) << ' ' << format_number(e.dtheta);
    io::write_upper<3>(out, e.information);
    out << '\n';
  }
  detail::traj_io::finish_output(out, file);
}

/// Reads 4-DoF loop edges (format in the file comment).
/// @throws posefuse::io_error (file:line) for a line without 16 fields, a
///         bad id or number, an edge from a node to itself, or an
///         information matrix that is not positive semi-definite; (file
///         only) when it cannot be read
template <class Lazy = void>
[[nodiscard]] std::vector<LoopEdge4DofRecord> read_loop_edges_4dof(const std::filesystem::path& file) {
  namespace io = detail::g2o_io;
  std::vector<LoopEdge4DofRecord> edges;
  detail::LineReader reader(file);
  std::string line;
  while (reader.next(line)) {
    if (detail::traj_io::is_blank_or_comment(line)) continue;
    const std::size_t n = reader.line_no();
    const std::vector<std::string_view> tok = detail::traj_io::split_whitespace(line);
    if (tok.size() != 16)
      throw io_error(file, n,
                     "expected 16 fields (i j x y z yaw I11 I12 I13 I14 I22 I23 I24 I33 I34 I44), found " +
                         std::to_string(tok.size()));
    LoopEdge4DofRecord e;
    e.from = io::parse_id(tok[0], file, n, 1);
    e.to = io::parse_id(tok[1], file, n, 2);
    if (e.from == e.to)
      throw io_error(file, n, "loop edge from node " + std::to_string(e.from) + " to itself");
    const std::vector<double> v = io::numbers(tok, 2, 14, file, n);
    e.dp = Eigen::Vector3d(v[0], v[1], v[2]);
    e.dyaw = v[3];
    e.information = io::from_upper<4>(v.data() + 4);
    io::check_information(e.information, file, n);
    e.line = n;
    edges.push_back(e);
  }
  return edges;
}

/// Writes 4-DoF loop edges (format in the file comment), round-trip exact.
/// @throws posefuse::io_error when the file cannot be written
template <class Lazy = void>
void write_loop_edges_4dof(const std::filesystem::path& file, const std::vector<LoopEdge4DofRecord>& edges) {
  using detail::traj_io::format_number;
  std::ofstream out = detail::traj_io::open_output(file);
  out << "# i j x y z yaw I11 I12 I13 I14 I22 I23 I24 I33 I34 I44 (posefuse 4-DoF loop edges)\n";
  for (const LoopEdge4DofRecord& e : edges) {
    out << e.from << ' ' << e.to << ' ' << format_number(e.dp.x()) << ' ' << format_number(e.dp.y()) << ' '
        << format_number(e.dp.z()) << ' ' << format_number(e.dyaw);
    detail::g2o_io::write_upper<4>(out, e.information);
    out << '\n';
  }
  detail::traj_io::finish_output(out, file);
}

}  // namespace posefuse
