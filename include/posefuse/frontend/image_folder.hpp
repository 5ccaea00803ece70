#pragma once
/// @file
/// A EuRoC camera folder (e.g. `mav0/cam0/`) read image by image for the
/// front end (frontend/klt_tracker.hpp). Needs OpenCV (core, imgcodecs).
///
///     cam0/data.csv      #timestamp [ns],filename
///                        1403715273262142976,1403715273262142976.png
///     cam0/data/*.png    the images, 8-bit grey
///     cam0/sensor.yaml   the camera (io/euroc_camera.hpp)
///
/// **data.csv.** Blank lines and lines starting with '#' are skipped; every
/// other line is `t_ns,filename` (spaces around the fields allowed), else a
/// posefuse::io_error `data.csv:line: reason`: not two fields, a stamp that
/// is not an int64 integer, an empty file name, a file name with a folder
/// part, a stamp not later than the previous line's (naming both lines), a
/// listed image that does not exist under `data/`. A file without rows is
/// an error too.
///
/// **Images** are read when asked for (EurocImageFolder::image): one that
/// cannot be decoded is refused naming the image file, and so is one whose
/// size differs from the expected size, naming both sizes.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include <posefuse/core/error.hpp>
#include <posefuse/io/detail/line_reader.hpp>
#include <posefuse/io/detail/text.hpp>
#include <posefuse/io/euroc.hpp>

namespace posefuse::frontend {

/// One image of the folder.
struct ImageEntry {
  std::int64_t t_ns = 0;         ///< its stamp (ns)
  std::filesystem::path file;    ///< `<folder>/data/<filename>`
  std::size_t line = 0;          ///< its line in data.csv (1-based)
};

/// The images of a EuRoC camera folder (file comment).
class EurocImageFolder {
 public:
  /// Reads `<folder>/data.csv` and checks that every listed image exists.
  /// @param[in] folder the camera folder (holding data.csv and data/)
  /// @param[in] width  expected image width (px); 0: any
  /// @param[in] height expected image height (px); 0: any
  /// @throws posefuse::io_error naming data.csv:line for each refusal of the
  ///         file comment, and data.csv when it cannot be read or lists no image
  EurocImageFolder(const std::filesystem::path& folder, int width, int height)
      : folder_(folder), csv_(folder / "data.csv"), width_(width), height_(height) {
    namespace fs = std::filesystem;
    detail::LineReader reader(csv_);
    std::string line;
    std::int64_t previous = 0;
    std::size_t previous_line = 0;
    while (reader.next(line)) {
      const std::size_t n = reader.line_no();
      if (detail::traj_io::is_blank_or_comment(line)) continue;
      const std::vector<std::string_view> f = detail::split_csv(line);
      if (f.size() != 2)
        throw io_error(csv_, n,
                       "expected 2 comma-separated fields (t_ns,filename), found " + std::to_string(f.size()));
      const std::int64_t t = detail::parse_stamp(f[0], csv_, n);
      if (previous_line > 0) detail::euroc_io::check_order(t, previous, previous_line, csv_, n);
      if (f[1].empty()) throw io_error(csv_, n, "empty file name");
      const fs::path name(f[1]);
      if (name.has_parent_path() || name.is_absolute() || name == "." || name == "..")
        throw io_error(csv_, n, "file name '" + std::string(f[1]) + "' must name a file in data/, without a folder");
      const fs::path file = folder_ / "data" / name;
      const fs::file_status st = detail::checked_status(file);
      if (!fs::is_regular_file(st))
        throw io_error(csv_, n,
                       "image " + file.string() + (fs::exists(st) ? " is not a regular file" : " does not exist"));
      entries_.push_back({t, file, n});
      previous = t;
      previous_line = n;
    }
    if (entries_.empty()) throw io_error(csv_, "lists no image (t_ns,filename rows)");
  }

  /// The listed images, stamps strictly increasing.
  [[nodiscard]] const std::vector<ImageEntry>& entries() const noexcept { return entries_; }
  /// Number of images.
  [[nodiscard]] std::size_t size() const noexcept { return entries_.size(); }
  /// `<folder>/data.csv`.
  [[nodiscard]] const std::filesystem::path& csv() const noexcept { return csv_; }

  /// Reads image `k` as 8-bit grey (a colour image is converted).
  /// @param[in] k index into entries()
  /// @return the image, CV_8UC1
  /// @throws posefuse::io_error naming the image file when it cannot be
  ///         decoded, or when its size differs from the expected one (both sizes named)
  /// @throws posefuse::invalid_argument when k is out of range
  [[nodiscard]] cv::Mat image(std::size_t k) const {
    if (k >= entries_.size())
      throw invalid_argument("EurocImageFolder::image: index " + std::to_string(k) + " of " +
                             std::to_string(entries_.size()) + " images");
    const ImageEntry& e = entries_[k];
    cv::Mat img = cv::imread(e.file.string(), cv::IMREAD_GRAYSCALE);
    if (img.empty())
      throw io_error(e.file, "cannot be read as an image (listed on " + csv_.string() + ":" +
                                 std::to_string(e.line) + ")");
    if (img.depth() != CV_8U) img.convertTo(img, CV_8U);
    if ((width_ > 0 && img.cols != width_) || (height_ > 0 && img.rows != height_))
      throw io_error(e.file, "the image is " + std::to_string(img.cols) + "x" + std::to_string(img.rows) +
                                 " px but the camera's resolution is " + std::to_string(width_) + "x" +
                                 std::to_string(height_) + " px");
    return img;
  }

 private:
  std::filesystem::path folder_, csv_;
  int width_ = 0, height_ = 0;
  std::vector<ImageEntry> entries_;
};

}  // namespace posefuse::frontend
