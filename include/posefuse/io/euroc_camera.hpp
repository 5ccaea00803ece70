#pragma once
/// @file
/// A camera's calibration from a EuRoC `sensor.yaml` (Burri et al., "The
/// EuRoC micro aerial vehicle datasets", IJRR 2016), e.g. `cam0/sensor.yaml`:
///
///     %YAML:1.0
///     sensor_type: camera
///     comment: VI-Sensor cam0 (MT9M034)
///     T_BS:
///       cols: 4
///       rows: 4
///       data: [0.0148655429818, -0.999880929698, 0.00414029679422, -0.0216401454975,
///              0.999557249008, 0.0149672133247, 0.025715529948, -0.064676986768,
///             -0.0257744366974, 0.00375618835797, 0.999660727178, 0.00981073058949,
///              0.0, 0.0, 0.0, 1.0]
///     rate_hz: 20
///     resolution: [752, 480]
///     camera_model: pinhole
///     intrinsics: [458.654, 457.296, 367.215, 248.375] #fu, fv, cu, cv
///     distortion_model: radial-tangential
///     distortion_coefficients: [-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05]
///
/// **What is read** (no YAML library: the subset such files use). Keys at
/// the start of a line (`key: value`); `#` starts a comment anywhere outside
/// quotes; `%YAML` / `---` lines are skipped. A list is a flow list
/// `[a, b, ...]`, which may continue over several lines until its `]`, or a
/// block list (`- a` lines below the key). `T_BS` is a mapping (indented
/// `rows:`, `cols:`, `data:` lines, or a flow mapping `{rows: 4, cols: 4,
/// data: [...]}`) or directly a list of 16 (row-major 4x4) or 12 (3x4)
/// numbers. Keys this reader does not use (`sensor_type`, `comment`, ...)
/// are skipped, whatever their value.
///
/// **Required**, each refused with `file:line` (or `file:` when the key is
/// missing) rather than filled in:
/// * `intrinsics: [fu, fv, cu, cv]`, finite, fu and fv > 0;
/// * `resolution: [width, height]`, positive integers;
/// * `camera_model: pinhole` (the only model supported);
/// * `distortion_model`: `radial-tangential` (or its other names `radtan`,
///   `plumb_bob`) with `distortion_coefficients: [k1, k2, p1, p2]` (a fifth,
///   k3, only when it is 0), or `none` with no or all-zero coefficients;
/// * `T_BS`: 4x4 with last row `0 0 0 1` (1e-9), its rotation orthonormal
///   within 1e-6 (then re-orthonormalised, io/detail/text.hpp).
///
/// `rate_hz` is optional (0 when absent), finite and > 0 when given. Every
/// number must be finite (`.nan`, `.inf` refused); a key given twice is an
/// error naming both lines.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <cstddef>
#include <filesystem>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include <posefuse/core/error.hpp>
#include <posefuse/io/detail/line_reader.hpp>
#include <posefuse/io/detail/sensor_yaml.hpp>
#include <posefuse/io/detail/text.hpp>

namespace posefuse {

/// A pinhole camera with radial-tangential distortion as a EuRoC
/// `sensor.yaml` states it (see the file comment); the camera model itself
/// is vio/camera.hpp (PinholeRadtan).
struct CameraCalibration {
  double fu = 0, fv = 0;  ///< focal lengths (px)
  double cu = 0, cv = 0;  ///< principal point (px)
  /// Radial-tangential coefficients k1, k2, p1, p2 (zero for `none`).
  std::array<double, 4> distortion{0, 0, 0, 0};
  int width = 0, height = 0;  ///< resolution (px)
  double rate_hz = 0;         ///< frame rate (Hz); 0 when the file does not state it
  /// \f$ T_{BS} \f$: sensor (camera) frame S to body frame B, p_B = T_BS * p_S.
  Eigen::Isometry3d T_BS = Eigen::Isometry3d::Identity();
};

namespace detail::camera_yaml {

/// A flat list of numbers read from key `key`, with its line.
template <class Lazy = void>
[[nodiscard]] std::vector<double> numbers(const sensor_yaml::Value& v, std::string_view key,
                                          const std::filesystem::path& file) {
  if (!v.is_list)
    throw io_error(file, v.line, "'" + std::string(key) + "' must be a list [a, b, ...]");
  std::vector<double> out;
  out.reserve(v.items.size());
  for (std::size_t i = 0; i < v.items.size(); ++i)
    out.push_back(sensor_yaml::parse_finite(v.items[i], key, i, file, v.item_lines[i]));
  return out;
}

/// The value of a required key.
template <class Lazy = void>
[[nodiscard]] const sensor_yaml::Value& required(const sensor_yaml::Document& doc,
                                                 const std::string& key,
                                                 const std::filesystem::path& file) {
  const auto it = doc.find(key);
  if (it == doc.end())
    throw io_error(file, "no '" + key + "' key (a EuRoC camera sensor.yaml needs intrinsics, "
                         "resolution, camera_model, distortion_model, distortion_coefficients and T_BS)");
  return it->second;
}

/// A scalar text value (lowercase not enforced; compared exactly).
template <class Lazy = void>
[[nodiscard]] std::string scalar(const sensor_yaml::Value& v, std::string_view key,
                                 const std::filesystem::path& file) {
  if (v.is_list || v.is_map)
    throw io_error(file, v.line, "'" + std::string(key) + "' must be a single value");
  return sensor_yaml::unquote(v.scalar);
}

/// T_BS from a mapping {rows, cols, data} or a plain list of 12 / 16 numbers.
template <class Lazy = void>
[[nodiscard]] Eigen::Isometry3d transform(const sensor_yaml::Document& doc,
                                          const std::filesystem::path& file) {
  const sensor_yaml::Value& v = required(doc, "T_BS", file);
  const sensor_yaml::Value* data = &v;
  if (v.is_map) {
    const auto it = v.children.find("data");
    if (it == v.children.end()) throw io_error(file, v.line, "T_BS has no 'data' list");
    data = &it->second;
    for (const char* k : {"rows", "cols"}) {
      const auto d = v.children.find(k);
      if (d == v.children.end()) continue;
      const std::string text = scalar(d->second, std::string("T_BS.") + k, file);
      if (text != "4")
        throw io_error(file, d->second.line,
                       "T_BS." + std::string(k) + " is " + text + "; only a 4x4 matrix is read");
    }
  } else if (!v.is_list) {
    throw io_error(file, v.line, "T_BS must be a 4x4 matrix (rows, cols, data) or a list of 16 numbers");
  }
  const std::vector<double> d = numbers(*data, "T_BS", file);
  if (d.size() != 16 && d.size() != 12)
    throw io_error(file, data->line,
                   "T_BS data has " + std::to_string(d.size()) +
                       " numbers; expected 16 (row-major 4x4) or 12 (3x4)");
  if (d.size() == 16) {
    const double dev = std::abs(d[12]) + std::abs(d[13]) + std::abs(d[14]) + std::abs(d[15] - 1.0);
    if (!(dev <= 1e-9))
      throw io_error(file, data->line,
                     "T_BS last row is not 0 0 0 1 (" + detail::message_number(d[12]) + " " +
                         detail::message_number(d[13]) + " " + detail::message_number(d[14]) + " " +
                         detail::message_number(d[15]) + ")");
  }
  Eigen::Matrix3d R;
  R << d[0], d[1], d[2], d[4], d[5], d[6], d[8], d[9], d[10];
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = traj_io::checked_rotation(R, 1e-6, file, data->line);
  T.translation() = Eigen::Vector3d(d[3], d[7], d[11]);
  return T;
}

}  // namespace detail::camera_yaml

/// Reads a camera calibration from a EuRoC `sensor.yaml` (file comment).
/// @param[in] file the yaml file
/// @return the calibration
/// @throws posefuse::io_error naming file:line for malformed lines and bad
///         values, and the file for a missing key (see the file comment)
template <class Lazy = void>
[[nodiscard]] CameraCalibration read_euroc_camera_calibration(const std::filesystem::path& file) {
  namespace cy = detail::camera_yaml;
  const detail::sensor_yaml::Document doc = detail::sensor_yaml::parse(file);
  CameraCalibration c;

  const detail::sensor_yaml::Value& model = cy::required(doc, "camera_model", file);
  const std::string model_name = cy::scalar(model, "camera_model", file);
  if (model_name != "pinhole")
    throw io_error(file, model.line,
                   "camera_model '" + model_name + "' is not supported (only 'pinhole')");

  const detail::sensor_yaml::Value& intr = cy::required(doc, "intrinsics", file);
  const std::vector<double> k = cy::numbers(intr, "intrinsics", file);
  if (k.size() != 4)
    throw io_error(file, intr.line,
                   "intrinsics has " + std::to_string(k.size()) + " numbers; expected 4 [fu, fv, cu, cv]");
  if (!(k[0] > 0 && k[1] > 0))
    throw io_error(file, intr.line, "intrinsics: the focal lengths fu, fv must be > 0");
  c.fu = k[0];
  c.fv = k[1];
  c.cu = k[2];
  c.cv = k[3];

  const detail::sensor_yaml::Value& res = cy::required(doc, "resolution", file);
  const std::vector<double> r = cy::numbers(res, "resolution", file);
  if (r.size() != 2)
    throw io_error(file, res.line, "resolution has " + std::to_string(r.size()) +
                                       " numbers; expected 2 [width, height]");
  for (const double x : r)
    if (!(x >= 1 && x <= 1e6 && x == std::floor(x)))
      throw io_error(file, res.line, "resolution: width and height must be positive integers");
  c.width = int(r[0]);
  c.height = int(r[1]);

  const detail::sensor_yaml::Value& dm = cy::required(doc, "distortion_model", file);
  const std::string dist_name = cy::scalar(dm, "distortion_model", file);
  const bool radtan = dist_name == "radial-tangential" || dist_name == "radtan" || dist_name == "plumb_bob";
  if (!radtan && dist_name != "none")
    throw io_error(file, dm.line,
                   "distortion_model '" + dist_name +
                       "' is not supported (radial-tangential, radtan, plumb_bob or none)");
  const auto coeff_it = doc.find("distortion_coefficients");
  std::vector<double> dc;
  if (coeff_it != doc.end()) dc = cy::numbers(coeff_it->second, "distortion_coefficients", file);
  const std::size_t coeff_line = coeff_it != doc.end() ? coeff_it->second.line : dm.line;
  if (radtan) {
    if (coeff_it == doc.end())
      throw io_error(file, dm.line, "distortion_model '" + dist_name +
                                        "' needs distortion_coefficients: [k1, k2, p1, p2]");
    if (dc.size() == 5 && dc[4] != 0.0)
      throw io_error(file, coeff_line,
                     "distortion_coefficients: k3 = " + detail::message_number(dc[4]) +
                         " is not supported (4 coefficients k1, k2, p1, p2, or k3 = 0)");
    if (dc.size() != 4 && dc.size() != 5)
      throw io_error(file, coeff_line,
                     "distortion_coefficients has " + std::to_string(dc.size()) +
                         " numbers; expected 4 [k1, k2, p1, p2]");
    for (std::size_t i = 0; i < 4; ++i) c.distortion[i] = dc[i];
  } else {
    for (const double x : dc)
      if (x != 0.0)
        throw io_error(file, coeff_line,
                       "distortion_model is 'none' but distortion_coefficients are not all zero");
  }

  if (const auto it = doc.find("rate_hz"); it != doc.end()) {
    const std::string text = cy::scalar(it->second, "rate_hz", file);
    c.rate_hz = detail::sensor_yaml::parse_finite(text, "rate_hz", 0, file, it->second.line);
    if (!(c.rate_hz > 0)) throw io_error(file, it->second.line, "rate_hz must be > 0");
  }
  c.T_BS = cy::transform(doc, file);
  return c;
}

}  // namespace posefuse
