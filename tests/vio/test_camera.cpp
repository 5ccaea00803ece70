// The pinhole radial-tangential camera (vio/camera.hpp) and its EuRoC
// sensor.yaml reader (io/euroc_camera.hpp): projection / undistortion round
// trip, the projection Jacobian through the conformance harness (with a
// flip test), the fold check, and file:line errors for malformed or
// incomplete files; the real EuRoC cam0 file when present.
#include <catch2/catch.hpp>

#include <cmath>
#include <string>

#include <posefuse/io/euroc_camera.hpp>
#include <posefuse/sim/feature_tracks.hpp>
#include <posefuse/testing/jacobian_check.hpp>
#include <posefuse/vio/camera.hpp>

#include "support/data_path.hpp"
#include "support/io_error.hpp"
#include "support/temp_dir.hpp"

namespace {

using posefuse::PinholeRadtan;

// The EuRoC V1_01_easy cam0 file as published (comments, T_BS data over
// four lines, %YAML header).
const char* kEurocCam0 = R"(%YAML:1.0
# General sensor definitions.
sensor_type: camera
comment: VI-Sensor cam0 (MT9M034)

# Sensor extrinsics wrt. the body-frame.
T_BS:
  cols: 4
  rows: 4
  data: [0.0148655429818, -0.999880929698, 0.00414029679422, -0.0216401454975,
         0.999557249008, 0.0149672133247, 0.025715529948, -0.064676986768,
        -0.0257744366974, 0.00375618835797, 0.999660727178, 0.00981073058949,
         0.0, 0.0, 0.0, 1.0]

# Camera specific definitions.
rate_hz: 20
resolution: [752, 480]
camera_model: pinhole
intrinsics: [458.654, 457.296, 367.215, 248.375] #fu, fv, cu, cv
distortion_model: radial-tangential
distortion_coefficients: [-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05]
)";

using posefuse::test::io_error_of;

// kEurocCam0 with the line starting with `key` replaced by `line` ("" drops it).
std::string with_line(const std::string& key, const std::string& line) {
  std::string s = kEurocCam0;
  const std::size_t at = s.find("\n" + key) + 1;
  const std::size_t end = s.find('\n', at);
  s.replace(at, end - at + 1, line.empty() ? "" : line + "\n");
  return s;
}

void check_euroc_cam0(const PinholeRadtan& c) {
  CHECK(c.fu == 458.654);
  CHECK(c.fv == 457.296);
  CHECK(c.cu == 367.215);
  CHECK(c.cv == 248.375);
  CHECK(c.distortion[0] == -0.28340811);
  CHECK(c.distortion[3] == 1.76187114e-05);
  CHECK(c.width == 752);
  CHECK(c.height == 480);
  CHECK(c.rate_hz == 20);
  CHECK(c.T_BS.translation().x() == -0.0216401454975);
  CHECK(c.T_BS.translation().z() == 0.00981073058949);
  // The published rotation is orthonormal to 5.8e-13, under the 1e-12 below
  // which a rotation is kept as written (io/detail/text.hpp).
  CHECK(c.T_BS.linear()(1, 0) == 0.999557249008);
  CHECK((c.T_BS.linear().transpose() * c.T_BS.linear() - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() < 1e-12);
}

}  // namespace

TEST_CASE("Camera: EuRoC sensor.yaml read as published", "[vio][camera]") {
  posefuse::test::TempDir dir("camera");
  check_euroc_cam0(posefuse::read_euroc_camera(dir.write("cam0.yaml", kEurocCam0)));
}

TEST_CASE("Camera: sensor.yaml variants a user may have", "[vio][camera]") {
  posefuse::test::TempDir dir("camera");
  // Flow mapping for T_BS, block lists, quoted values, extra keys, CRLF, a
  // nested row-list and an OpenCV tag.
  const std::string variant =
      "sensor_type: \"camera\"\r\n"
      "extra_map:\r\n  a: 1\r\n  b: [1, 2]\r\n"
      "T_BS: {rows: 4, cols: 4, data: [[0.0148655429818, -0.999880929698, 0.00414029679422, -0.0216401454975],\r\n"
      "   [0.999557249008, 0.0149672133247, 0.025715529948, -0.064676986768],\r\n"
      "   [-0.0257744366974, 0.00375618835797, 0.999660727178, 0.00981073058949], [0, 0, 0, 1]]}\r\n"
      "rate_hz: 20.0   # Hz\r\n"
      "resolution:\r\n- 752\r\n- 480\r\n"
      "camera_model: 'pinhole'\r\n"
      "intrinsics: !!floats [458.654, 457.296,\r\n   367.215, 248.375]\r\n"
      "distortion_model: radtan\r\n"
      "distortion_coefficients:\r\n  - -0.28340811\r\n  - 0.07395907\r\n  - 0.00019359\r\n  - 1.76187114e-05\r\n";
  check_euroc_cam0(posefuse::read_euroc_camera(dir.write("variant.yaml", variant)));
  // 3x4 T_BS as a plain list, no rate, distortion none.
  const auto plain = dir.write("plain.yaml",
                               "T_BS: [1, 0, 0, 0.1, 0, 1, 0, 0.2, 0, 0, 1, 0.3]\n"
                               "resolution: [640, 480]\ncamera_model: pinhole\n"
                               "intrinsics: [500, 500, 320, 240]\ndistortion_model: none\n");
  const PinholeRadtan c = posefuse::read_euroc_camera(plain);
  CHECK(c.rate_hz == 0);
  CHECK(c.distortion == std::array<double, 4>{0, 0, 0, 0});
  CHECK(c.T_BS.translation() == Eigen::Vector3d(0.1, 0.2, 0.3));
}

TEST_CASE("Camera: sensor.yaml errors name file:line or the missing key", "[vio][camera]") {
  posefuse::test::TempDir dir("camera");
  const auto err = [&](const std::string& text) {
    const auto f = dir.write("c.yaml", text);
    return io_error_of([&] { (void)posefuse::read_euroc_camera(f); });
  };
  CHECK_THAT(err(with_line("intrinsics", "")), Catch::Contains("c.yaml: no 'intrinsics' key"));
  CHECK_THAT(err(with_line("intrinsics", "intrinsics: [458.654, 457.296, 367.215]")),
             Catch::Contains("c.yaml:19: intrinsics has 3 numbers"));
  CHECK_THAT(err(with_line("intrinsics", "intrinsics: [458.654, .nan, 367.215, 248.375]")),
             Catch::Contains("c.yaml:19: intrinsics item 2: cannot parse '.nan'"));
  CHECK_THAT(err(with_line("intrinsics", "intrinsics: [458.654, nan, 367.215, 248.375]")),
             Catch::Contains("c.yaml:19: intrinsics item 2: non-finite value 'nan'"));
  CHECK_THAT(err(with_line("intrinsics", "intrinsics: [-458.654, 457.296, 367.215, 248.375]")),
             Catch::Contains("c.yaml:19: intrinsics: the focal lengths"));
  CHECK_THAT(err(with_line("distortion_model", "distortion_model: equidistant")),
             Catch::Contains("c.yaml:20: distortion_model 'equidistant' is not supported"));
  CHECK_THAT(err(with_line("distortion_model", "")), Catch::Contains("c.yaml: no 'distortion_model' key"));
  CHECK_THAT(err(with_line("camera_model", "camera_model: omni")),
             Catch::Contains("c.yaml:18: camera_model 'omni' is not supported"));
  CHECK_THAT(err(with_line("distortion_coefficients", "distortion_coefficients: [-0.28, 0.07, 0.0002]")),
             Catch::Contains("c.yaml:21: distortion_coefficients has 3 numbers"));
  CHECK_THAT(err(with_line("distortion_coefficients", "distortion_coefficients: [-0.28, 0.07, 0, 0, 0.01]")),
             Catch::Contains("c.yaml:21: distortion_coefficients: k3 = 0.01 is not supported"));
  CHECK_THAT(err(with_line("resolution", "resolution: [752.5, 480]")),
             Catch::Contains("c.yaml:17: resolution: width and height must be positive integers"));
  CHECK_THAT(err(with_line("rate_hz", "rate_hz: 20\nrate_hz: 30")),
             Catch::Contains("c.yaml:17: key 'rate_hz' repeats the one on line 16"));
  // T_BS: data over lines 10-13; a bad number is reported on its own line.
  std::string bad = kEurocCam0;
  bad.replace(bad.find("0.999557249008"), 14, "0.99955724900x");
  CHECK_THAT(err(bad), Catch::Contains("c.yaml:11: T_BS item 5: cannot parse '0.99955724900x'"));
  std::string unclosed = kEurocCam0;
  unclosed.replace(unclosed.find("1.0]"), 4, "1.0 ");
  CHECK_THAT(err(unclosed), Catch::Contains("c.yaml:10: the list or mapping opened here is not closed"));
  std::string not_rigid = kEurocCam0;
  not_rigid.replace(not_rigid.find("0.0148655429818"), 15, "0.5148655429818");
  CHECK_THAT(err(not_rigid), Catch::Contains("c.yaml:10: rotation is not orthonormal"));
  CHECK_THAT(err(std::string(kEurocCam0) + "  stray: 1\n"),
             Catch::Contains("c.yaml:22: unexpected indentation"));
  CHECK_THAT(err(std::string(kEurocCam0) + "no colon here\n"), Catch::Contains("c.yaml:22: expected 'key: value'"));
  // A distortion that folds inside the image is refused, naming the file.
  CHECK_THAT(err(with_line("distortion_coefficients", "distortion_coefficients: [-0.9, 0.0, 0, 0]")),
             Catch::Contains("c.yaml: the camera is not usable: the distortion cannot be inverted"));
}

TEST_CASE("Camera: projection and undistortion round trip over the image", "[vio][camera]") {
  const PinholeRadtan cam = posefuse::sim::synthetic_camera();  // EuRoC cam0 intrinsics
  double worst_px = 0, worst_xy = 0;
  int inside = 0;
  for (int i = 0; i <= 40; ++i) {
    for (int j = 0; j <= 40; ++j) {
      const Eigen::Vector2d uv(751.0 * i / 40, 479.0 * j / 40);  // border pixel centres included
      const Eigen::Vector2d xy = cam.undistort(uv);
      REQUIRE(xy.allFinite());
      const double depth = 0.5 + 0.1 * (i + j);
      const std::optional<Eigen::Vector2d> back = cam.project(Eigen::Vector3d(xy.x(), xy.y(), 1.0) * depth);
      REQUIRE(back);
      worst_px = std::max(worst_px, (*back - uv).norm());
      // Normalised -> pixel -> normalised.
      worst_xy = std::max(worst_xy, (cam.undistort(cam.pixel_of_normalised(xy)) - xy).norm());
      ++inside;
    }
  }
  CHECK(inside == 41 * 41);
  CHECK(worst_px < 1e-9);
  // Newton stops at a 1e-12 residual of the distorted coordinates; divided by
  // the distortion's slope (below 1 towards the image's edge) that is a few 1e-12.
  INFO("worst_xy " << worst_xy);
  CHECK(worst_xy < 1e-11);
  // Behind, beside and far outside the image: no pixel.
  CHECK_FALSE(cam.project(Eigen::Vector3d(0, 0, -1)));
  CHECK_FALSE(cam.project(Eigen::Vector3d(0, 0, 0)));
  CHECK_FALSE(cam.project(Eigen::Vector3d(5, 0, 1)));
  CHECK(cam.in_image({-0.5, -0.5}));
  CHECK(cam.in_image({751.5, 479.5}));
  CHECK_FALSE(cam.in_image({751.6, 100}));
  CHECK_FALSE(cam.in_image({100, -0.51}));
}

TEST_CASE("Camera: a point beyond the distortion's fold is not projected", "[vio][camera]") {
  PinholeRadtan cam = posefuse::sim::synthetic_camera();
  cam.distortion = {-0.3, 0.0, 0.0, 0.0};  // r_d = r (1 - 0.3 r^2) folds at r^2 = 1/0.9
  CHECK(cam.max_valid_r2() == Approx(1.0 / 0.9).epsilon(1e-15));
  // r^2 = 2.5: r_d = 1.58 (1 - 0.75) = 0.40 would land inside the image.
  const Eigen::Vector3d far(std::sqrt(2.5), 0, 1);
  CHECK(cam.pixel_of_normalised(far.head<2>()).x() < 752);
  CHECK_FALSE(cam.project(far));
}

TEST_CASE("Camera: projection Jacobian through the conformance harness", "[vio][camera][jacobian]") {
  const PinholeRadtan cam = posefuse::sim::synthetic_camera();
  const auto f = [&](const Eigen::Vector3d& p) {
    const std::optional<Eigen::Vector2d> uv = cam.project(p);
    return uv ? *uv : Eigen::Vector2d::Constant(std::nan(""));
  };
  for (const Eigen::Vector3d& p : {Eigen::Vector3d(0.1, -0.2, 2.0), Eigen::Vector3d(-0.9, 0.5, 1.5),
                                  Eigen::Vector3d(0.7, 0.45, 1.0), Eigen::Vector3d(0.0, 0.0, 0.8)}) {
    Eigen::Matrix<double, 2, 3> J;
    REQUIRE(cam.project(p, &J));
    // Entries are up to ~500 px/m: 1e-6 relative to (1 + |J|) as the harness states.
    const posefuse::testing::CheckResult r = posefuse::testing::check_jacobian("d uv / d p_C", f, p, J, 1e-6);
    INFO(r.message);
    CHECK(r.ok);
    Eigen::Matrix<double, 2, 3> flipped = J;
    flipped(0, 0) = -flipped(0, 0);
    CHECK_FALSE(posefuse::testing::check_jacobian("flipped", f, p, flipped, 1e-6).ok);
  }
  // The distortion's own Jacobian.
  const Eigen::Vector2d xy(0.6, -0.4);
  Eigen::Matrix2d Jd;
  (void)cam.distort(xy, &Jd);
  const auto g = [&](const Eigen::Vector2d& v) { return cam.distort(v); };
  CHECK(posefuse::testing::check_jacobian("d distort / d xy", g, xy, Jd, 1e-8).ok);
}

TEST_CASE("Camera: the real EuRoC V1_01_easy cam0 sensor.yaml", "[vio][camera][data]") {
  POSEFUSE_REQUIRE_DATASET(d, "euroc/V1_01_easy");
  check_euroc_cam0(posefuse::read_euroc_camera(d / "cam0_sensor.yaml"));
}
