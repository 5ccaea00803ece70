#pragma once
/// @file
/// The one way a number is printed in an error or warning message: short
/// enough to read, exact when the value is short.
///
/// A value whose shortest round-trip text has at most 6 significant digits is
/// printed as that text ("0.05", "1e-09", "1e+308", "-3"); any other value
/// with 6 significant digits, as printf's %g does ("105" for
/// 104.99993599999999, "2.00000" -> "2", "-1.00017"). Small and large
/// magnitudes are in scientific notation, so a limit of 1e-9 s never reads
/// "0.000000 s". Files are written with the shortest round-trip text
/// instead (traj_io::format_number), never with this.

#include <charconv>
#include <cmath>
#include <cstdio>
#include <string>

namespace posefuse::detail {

/// `value` for a message; see the file comment.
[[nodiscard]] inline std::string message_number(double value) {
  if (std::isnan(value)) return "nan";
  if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
  char buf[64];
  const auto [ptr, ec] = std::to_chars(buf, buf + sizeof buf, value);
  (void)ec;  // 64 characters always suffice for a double
  const std::string shortest(buf, ptr);
  int digits = 0;
  bool leading = true;
  for (const char c : shortest) {
    if (c == 'e' || c == 'E') break;
    if (c < '0' || c > '9') continue;
    if (leading && c == '0') continue;  // zeros before the first significant digit
    leading = false;
    ++digits;
  }
  // Trailing zeros of an integer ("1000000") are not significant either.
  if (shortest.find_first_of(".e") == std::string::npos)
    for (auto it = shortest.rbegin(); it != shortest.rend() && *it == '0' && digits > 1; ++it) --digits;
  if (digits <= 6) return shortest;
  std::snprintf(buf, sizeof buf, "%.6g", value);
  return buf;
}

}  // namespace posefuse::detail
