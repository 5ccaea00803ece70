#pragma once
// Synthetic images for the front-end tests: a procedural texture (seeded
// noise low-passed into blobs) and its views under a known affine motion, so
// that where each tracked point must go is known exactly.
#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <posefuse/vio/camera.hpp>

namespace posefuse_test::frontend {

inline constexpr int kWidth = 752, kHeight = 480;  // EuRoC's resolution (px)
inline constexpr int kMargin = 64;                 // texture beyond the image on every side (px)

// Seeded noise blurred into blobs of a few pixels, float, about 20..235:
// (kWidth + 2 kMargin) x (kHeight + 2 kMargin).
inline cv::Mat texture(std::uint32_t seed = 7, double blur_sigma_px = 2.5) {
  cv::Mat t(kHeight + 2 * kMargin, kWidth + 2 * kMargin, CV_32FC1);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (int r = 0; r < t.rows; ++r)
    for (int c = 0; c < t.cols; ++c) t.at<float>(r, c) = u(rng);
  cv::GaussianBlur(t, t, cv::Size(0, 0), blur_sigma_px);
  cv::normalize(t, t, 20.0, 235.0, cv::NORM_MINMAX);
  return t;
}

// The image of the texture moved by the affine map p' = c + A (p - c) + shift,
// with c the image centre: pixel p' of the new image shows texture point p.
// A = scale * R(angle).
inline cv::Mat view(const cv::Mat& tex, double dx, double dy, double angle_rad = 0.0, double scale = 1.0) {
  const double ca = scale * std::cos(angle_rad), sa = scale * std::sin(angle_rad);
  const double cx = kMargin + kWidth / 2.0, cy = kMargin + kHeight / 2.0;
  // forward map in texture coordinates
  cv::Matx23d M(ca, -sa, cx - ca * cx + sa * cy + dx, sa, ca, cy - sa * cx - ca * cy + dy);
  cv::Mat moved;
  cv::warpAffine(tex, moved, M, tex.size(), cv::INTER_CUBIC, cv::BORDER_REFLECT_101);
  cv::Mat img;
  moved(cv::Rect(kMargin, kMargin, kWidth, kHeight)).convertTo(img, CV_8UC1);  // rounds
  return img;
}

// Where a pixel of the unmoved image goes under view(tex, dx, dy, angle, scale).
inline Eigen::Vector2d moved_pixel(const Eigen::Vector2d& p, double dx, double dy, double angle_rad = 0.0,
                                   double scale = 1.0) {
  const Eigen::Vector2d c(kWidth / 2.0, kHeight / 2.0);
  Eigen::Matrix2d A;
  A << std::cos(angle_rad), -std::sin(angle_rad), std::sin(angle_rad), std::cos(angle_rad);
  return c + scale * A * (p - c) + Eigen::Vector2d(dx, dy);
}

// A distortion-free camera of the synthetic images' size.
inline posefuse::PinholeRadtan pinhole() {
  posefuse::PinholeRadtan cam;
  cam.fu = cam.fv = 460.0;
  cam.cu = kWidth / 2.0;
  cam.cv = kHeight / 2.0;
  cam.width = kWidth;
  cam.height = kHeight;
  return cam;
}

// EuRoC cam0's intrinsics and distortion (V1_01 sensor.yaml).
inline posefuse::PinholeRadtan euroc_cam0() {
  posefuse::PinholeRadtan cam;
  cam.fu = 458.654;
  cam.fv = 457.296;
  cam.cu = 367.215;
  cam.cv = 248.375;
  cam.distortion = {-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05};
  cam.width = kWidth;
  cam.height = kHeight;
  return cam;
}

// A sensor.yaml for a camera of w x h px (no distortion).
inline std::string sensor_yaml(int w, int h) {
  return "%YAML:1.0\nsensor_type: camera\nT_BS:\n  cols: 4\n  rows: 4\n  data: [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, "
         "0, 0, 0, 1]\nrate_hz: 20\nresolution: [" +
         std::to_string(w) + ", " + std::to_string(h) +
         "]\ncamera_model: pinhole\nintrinsics: [460, 460, " + std::to_string(w / 2) + ", " + std::to_string(h / 2) +
         "]\ndistortion_model: radial-tangential\ndistortion_coefficients: [0, 0, 0, 0]\n";
}

// Writes a EuRoC camera folder: data.csv, data/<stamp>.png, sensor.yaml.
// Frame k is the texture shifted by k * (dx, dy) px; stamps 50 ms apart.
inline void write_folder(const std::filesystem::path& dir, int frames, double dx, double dy) {
  std::filesystem::create_directories(dir / "data");
  const cv::Mat tex = texture();
  std::string csv = "#timestamp [ns],filename\n";
  for (int k = 0; k < frames; ++k) {
    const std::int64_t t = 1'000'000'000LL + k * 50'000'000LL;
    const std::string name = std::to_string(t) + ".png";
    cv::imwrite((dir / "data" / name).string(), view(tex, k * dx, k * dy));
    csv += std::to_string(t) + "," + name + "\n";
  }
  std::FILE* f = std::fopen((dir / "data.csv").string().c_str(), "wb");
  std::fputs(csv.c_str(), f);
  std::fclose(f);
  f = std::fopen((dir / "sensor.yaml").string().c_str(), "wb");
  std::fputs(sensor_yaml(kWidth, kHeight).c_str(), f);
  std::fclose(f);
}

}  // namespace posefuse_test::frontend
