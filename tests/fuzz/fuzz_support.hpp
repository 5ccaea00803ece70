#pragma once
/// @file
/// Shared pieces of the libFuzzer harnesses (tests/fuzz/fuzz_*.cpp) and of
/// the seed-corpus generator (make_seed_corpus.cpp): a per-process scratch
/// folder for the file readers, splitting an input at separator bytes, the
/// byte encoding of numbers used by the EKF harness, and the way a harness
/// reports a finding (message on stderr, then abort(), which libFuzzer turns
/// into a crash report with the input saved as an artifact).

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <numbers>
#include <string>
#include <string_view>
#include <system_error>
#include <type_traits>
#include <unistd.h>
#include <vector>

namespace posefuse_fuzz {

/// Reports a violated property and aborts (a finding for libFuzzer).
/// @param[in] what the property, with the values that break it
[[noreturn]] inline void finding(const std::string& what) {
  std::fprintf(stderr, "\nposefuse fuzz finding: %s\n", what.c_str());
  std::fflush(stderr);
  std::abort();
}

/// Reports a finding unless `ok`. `what` is the message, or a callable
/// returning it (built only when the check fails: harness hot paths).
template <class What>
inline void require(bool ok, const What& what) {
  if (ok) return;
  if constexpr (std::is_invocable_v<const What&>) {
    finding(std::string(what()));
  } else {
    finding(std::string(what));
  }
}

/// The separator between the files of one fuzz input (KITTI poses and
/// times.txt; the files of a robot-log folder).
inline constexpr char kFileSeparator = '\0';

/// Splits `data` at kFileSeparator into at most `max_parts` parts (the last
/// part keeps any further separators).
[[nodiscard]] inline std::vector<std::string_view> split_files(const std::uint8_t* data,
                                                              std::size_t size,
                                                              std::size_t max_parts) {
  std::string_view rest(reinterpret_cast<const char*>(data), size);
  std::vector<std::string_view> parts;
  while (parts.size() + 1 < max_parts) {
    const std::size_t at = rest.find(kFileSeparator);
    if (at == std::string_view::npos) break;
    parts.push_back(rest.substr(0, at));
    rest.remove_prefix(at + 1);
  }
  parts.push_back(rest);
  return parts;
}

/// Joins files into one fuzz input (the inverse of split_files).
[[nodiscard]] inline std::string join_files(const std::vector<std::string>& files) {
  std::string out;
  for (std::size_t i = 0; i < files.size(); ++i) {
    if (i > 0) out += kFileSeparator;
    out += files[i];
  }
  return out;
}

/// Writes `bytes` to `file` (truncating).
inline void write_bytes(const std::filesystem::path& file, std::string_view bytes) {
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  out.flush();
  if (!out) finding("harness: cannot write scratch file " + file.string());
}

/// A folder private to this process (so parallel fuzzing jobs do not share
/// files), created on first use and removed at exit.
class ScratchDir {
 public:
  explicit ScratchDir(std::string_view harness)
      : dir_(std::filesystem::temp_directory_path() /
             ("posefuse-fuzz-" + std::string(harness) + "-" + std::to_string(::getpid()))) {
    std::filesystem::create_directories(dir_);
  }
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;
  ~ScratchDir() {
    std::error_code ec;
    std::filesystem::remove_all(dir_, ec);
  }
  /// The folder.
  [[nodiscard]] const std::filesystem::path& path() const noexcept { return dir_; }
  /// A path inside the folder.
  [[nodiscard]] std::filesystem::path operator/(std::string_view name) const { return dir_ / name; }

 private:
  std::filesystem::path dir_;
};

/// True when a and b have the same bits, or are both NaN (whose payload the
/// text formats do not keep).
[[nodiscard]] inline bool same_number(double a, double b) noexcept {
  if (std::isnan(a) && std::isnan(b)) return true;
  return std::memcmp(&a, &b, sizeof a) == 0;
}

// ---------------------------------------------------------------------------
// Numbers as bytes (EKF harness). A number starts with a selector byte s:
//   s <  32 : kSpecial[s]          (zeros, +-1, tiny, huge, DBL_MAX, Inf, NaN)
//   s < 192 : int16 (next 2 bytes, little endian) / 64   (moderate values)
//   else    : the next 8 bytes as an IEEE double         (anything)
// Missing bytes read as 0, so every input decodes to something.
// ---------------------------------------------------------------------------

/// The special values a selector byte below 32 stands for.
inline constexpr double kSpecial[32] = {
    0.0,
    -0.0,
    1.0,
    -1.0,
    2.0,
    0.5,
    1e-3,
    -1e-3,
    1e3,
    1e-8,
    1e8,
    1e-150,
    1e150,
    -1e150,
    1e-300,
    1e300,
    -1e300,
    std::numeric_limits<double>::max(),
    -std::numeric_limits<double>::max(),
    std::numeric_limits<double>::min(),
    std::numeric_limits<double>::denorm_min(),
    -std::numeric_limits<double>::denorm_min(),
    std::numeric_limits<double>::epsilon(),
    1.0 + std::numeric_limits<double>::epsilon(),
    1.0 - std::numeric_limits<double>::epsilon() / 2,
    std::numbers::pi,
    -std::numbers::pi,
    2 * std::numbers::pi,
    std::numeric_limits<double>::infinity(),
    -std::numeric_limits<double>::infinity(),
    std::numeric_limits<double>::quiet_NaN(),
    -std::numeric_limits<double>::quiet_NaN(),
};

/// Reads bytes, numbers and choices from a fuzz input.
class ByteReader {
 public:
  ByteReader(const std::uint8_t* data, std::size_t size) noexcept : p_(data), n_(size) {}
  /// True when every byte has been read.
  [[nodiscard]] bool empty() const noexcept { return n_ == 0; }
  /// The next byte (0 past the end).
  std::uint8_t byte() noexcept {
    if (n_ == 0) return 0;
    --n_;
    return *p_++;
  }
  /// A choice in [0, n).
  std::size_t choice(std::size_t n) noexcept { return byte() % n; }
  /// A number (see the encoding above).
  double real() noexcept {
    const std::uint8_t s = byte();
    if (s < 32) return kSpecial[s];
    if (s < 192) {
      const auto lo = static_cast<std::uint16_t>(byte());
      const auto hi = static_cast<std::uint16_t>(byte());
      const auto v = static_cast<std::int16_t>(static_cast<std::uint16_t>(lo | (hi << 8)));
      return static_cast<double>(v) / 64.0;
    }
    std::uint8_t raw[8] = {};
    for (std::uint8_t& b : raw) b = byte();
    double v = 0;
    std::memcpy(&v, raw, sizeof v);
    return v;
  }

 private:
  const std::uint8_t* p_;
  std::size_t n_;
};

/// Writes what ByteReader reads (seed corpus).
class ByteWriter {
 public:
  /// One byte.
  ByteWriter& byte(std::uint8_t b) {
    bytes_.push_back(static_cast<char>(b));
    return *this;
  }
  /// The special value kSpecial[i].
  ByteWriter& special(std::uint8_t i) { return byte(i % 32); }
  /// A moderate value, rounded to a multiple of 1/64 in [-512, 512).
  ByteWriter& moderate(double v) {
    const long q = std::lround(v * 64.0);
    const auto c = static_cast<std::int16_t>(q < -32768 ? -32768 : q > 32767 ? 32767 : q);
    const auto u = static_cast<std::uint16_t>(c);
    byte(100).byte(static_cast<std::uint8_t>(u & 0xFF)).byte(static_cast<std::uint8_t>(u >> 8));
    return *this;
  }
  /// Any double, bit for bit.
  ByteWriter& raw(double v) {
    byte(200);
    std::uint8_t b[8];
    std::memcpy(b, &v, sizeof v);
    for (const std::uint8_t x : b) byte(x);
    return *this;
  }
  /// The bytes written so far.
  [[nodiscard]] const std::string& bytes() const noexcept { return bytes_; }

 private:
  std::string bytes_;
};

}  // namespace posefuse_fuzz
