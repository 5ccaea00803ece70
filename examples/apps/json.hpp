#pragma once
/// @file
/// A small streaming JSON writer (RFC 8259) for the example programs' `--json`.
///
///     std::ostringstream s;
///     apps::JsonWriter j(s);
///     j.begin_object();
///     j.member("rmse", 0.75).member("name", "orbslam2").key("errors").begin_array();
///     for (double e : errors) j.value(e);
///     j.end_array().end_object().finish();
///
/// Strings are escaped completely (quote, backslash, every control character;
/// invalid UTF-8 becomes U+FFFD), numbers are the shortest text that reads
/// back to the same double, and non-finite numbers are written as `null`, so
/// the output is always valid JSON. Containers are laid out one member per
/// line (Layout::kBlock, the default for objects) or on one line
/// (Layout::kInline, the default for arrays); everything inside an inline
/// container is inline.

#include <charconv>
#include <cmath>
#include <concepts>
#include <cstdint>
#include <ostream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace posefuse::apps {

namespace detail {

/// Length of the valid UTF-8 sequence at s[i], or 0 when the bytes there are
/// not one (overlong forms, surrogates and code points above U+10FFFF are invalid).
[[nodiscard]] inline std::size_t json_utf8_length(std::string_view s, std::size_t i) noexcept {
  const auto b = [&](std::size_t k) { return static_cast<unsigned char>(s[k]); };
  const unsigned char c = b(i);
  std::size_t n = 0;
  std::uint32_t cp = 0;
  if (c < 0x80) return 1;
  if (c >= 0xC2 && c <= 0xDF) n = 2, cp = c & 0x1Fu;
  else if (c >= 0xE0 && c <= 0xEF) n = 3, cp = c & 0x0Fu;
  else if (c >= 0xF0 && c <= 0xF4) n = 4, cp = c & 0x07u;
  else return 0;
  if (i + n > s.size()) return 0;
  for (std::size_t k = 1; k < n; ++k) {
    if ((b(i + k) & 0xC0u) != 0x80u) return 0;
    cp = (cp << 6) | (b(i + k) & 0x3Fu);
  }
  if ((n == 3 && cp < 0x800) || (n == 4 && cp < 0x10000) || cp > 0x10FFFF ||
      (cp >= 0xD800 && cp <= 0xDFFF))
    return 0;
  return n;
}

}  // namespace detail

/// Streaming JSON writer; see the file comment. Misuse (a value in an object
/// without a key, a key in an array, unbalanced ends, two top-level values)
/// is a programming error and throws std::logic_error.
class JsonWriter {
 public:
  /// How a container is laid out.
  enum class Layout {
    kBlock,   ///< one member per line, indented by two spaces a level
    kInline,  ///< all on one line: `{"a": 1, "b": [1, 2]}`
  };

  /// @param[in] out the stream written to (kept by reference)
  explicit JsonWriter(std::ostream& out) : out_(out) {}

  /// Opens an object.
  JsonWriter& begin_object(Layout layout = Layout::kBlock) { return open('{', layout); }
  /// Closes the innermost object.
  JsonWriter& end_object() { return close('}'); }
  /// Opens an array.
  JsonWriter& begin_array(Layout layout = Layout::kInline) { return open('[', layout); }
  /// Closes the innermost array.
  JsonWriter& end_array() { return close(']'); }

  /// Writes a member name; the next value or container is its value.
  JsonWriter& key(std::string_view name) {
    if (stack_.empty() || stack_.back().close != '}' || stack_.back().has_key)
      throw std::logic_error("JsonWriter: key '" + std::string(name) + "' outside an object");
    separate();
    out_ << quote(name) << ": ";
    stack_.back().has_key = true;
    return *this;
  }

  /// A string value.
  JsonWriter& value(std::string_view s) { return scalar(quote(s)); }
  /// A string value (not a bool).
  JsonWriter& value(const char* s) { return value(std::string_view(s)); }
  /// A string value.
  JsonWriter& value(const std::string& s) { return value(std::string_view(s)); }
  /// `true` or `false`.
  JsonWriter& value(bool b) { return scalar(b ? "true" : "false"); }
  /// A number, shortest round-trip text; `null` when not finite.
  JsonWriter& value(double v) { return scalar(number(v)); }
  /// An integer, exactly.
  template <std::integral T>
    requires(!std::same_as<T, bool> && !std::same_as<T, char>)
  JsonWriter& value(T v) {
    return scalar(std::to_string(v));
  }
  /// `null`.
  JsonWriter& null() { return scalar("null"); }

  /// `key(name).value(v)`.
  template <class T>
  JsonWriter& member(std::string_view name, const T& v) {
    key(name);
    return value(v);
  }

  /// Ends the document with a newline.
  /// @throws std::logic_error when a container is still open or nothing was written
  void finish() {
    if (!stack_.empty() || !done_) throw std::logic_error("JsonWriter: unfinished document");
    out_ << '\n';
  }

  /// `s` as a JSON string literal, quotes included.
  [[nodiscard]] static std::string quote(std::string_view s) {
    static constexpr char kHex[] = "0123456789abcdef";
    std::string q = "\"";
    for (std::size_t i = 0; i < s.size();) {
      const unsigned char c = static_cast<unsigned char>(s[i]);
      switch (c) {
        case '"': q += "\\\""; break;
        case '\\': q += "\\\\"; break;
        case '\b': q += "\\b"; break;
        case '\f': q += "\\f"; break;
        case '\n': q += "\\n"; break;
        case '\r': q += "\\r"; break;
        case '\t': q += "\\t"; break;
        default:
          if (c < 0x20 || c == 0x7F) {
            q += "\\u00";
            q += kHex[c >> 4];
            q += kHex[c & 0xF];
          } else if (c >= 0x80) {
            const std::size_t n = detail::json_utf8_length(s, i);
            if (n == 0) {
              q += "\\ufffd";  // not UTF-8: the replacement character
              ++i;
            } else {
              q.append(s.substr(i, n));
              i += n;
            }
            continue;
          } else {
            q += static_cast<char>(c);
          }
      }
      ++i;
    }
    q += '"';
    return q;
  }

  /// `v` as a JSON number: the shortest text that reads back to the same
  /// double (std::to_chars, locale-free), `null` when not finite.
  [[nodiscard]] static std::string number(double v) {
    if (!std::isfinite(v)) return "null";
    char buf[64];
    const auto [ptr, ec] = std::to_chars(buf, buf + sizeof buf, v);
    (void)ec;  // 64 characters always suffice for a double
    return std::string(buf, ptr);
  }

 private:
  struct Level {
    char close;
    bool is_inline;
    std::size_t count = 0;
    bool has_key = false;
  };

  void separate() {
    if (stack_.empty()) {
      if (done_) throw std::logic_error("JsonWriter: a second top-level value");
      return;
    }
    Level& l = stack_.back();
    if (l.close == '}' && l.has_key) return;  // the value of a key: same line
    if (l.count > 0) out_ << ',';
    if (l.is_inline) {
      if (l.count > 0) out_ << ' ';
    } else {
      out_ << '\n' << std::string(2 * stack_.size(), ' ');
    }
  }

  void element_written() {
    if (stack_.empty()) {
      done_ = true;
      return;
    }
    Level& l = stack_.back();
    if (l.close == '}' && !l.has_key)
      throw std::logic_error("JsonWriter: a value in an object needs a key");
    l.has_key = false;
    ++l.count;
  }

  JsonWriter& scalar(std::string_view text) {
    check_value_allowed();
    separate();
    out_ << text;
    element_written();
    return *this;
  }

  void check_value_allowed() const {
    if (!stack_.empty() && stack_.back().close == '}' && !stack_.back().has_key)
      throw std::logic_error("JsonWriter: a value in an object needs a key");
  }

  JsonWriter& open(char bracket, Layout layout) {
    check_value_allowed();
    separate();
    out_ << bracket;
    const bool parent_inline = !stack_.empty() && stack_.back().is_inline;
    stack_.push_back({bracket == '{' ? '}' : ']', parent_inline || layout == Layout::kInline});
    return *this;
  }

  JsonWriter& close(char bracket) {
    if (stack_.empty() || stack_.back().close != bracket || stack_.back().has_key)
      throw std::logic_error(std::string("JsonWriter: unbalanced '") + bracket + "'");
    const Level l = stack_.back();
    stack_.pop_back();
    if (!l.is_inline && l.count > 0) out_ << '\n' << std::string(2 * stack_.size(), ' ');
    out_ << bracket;
    element_written();
    return *this;
  }

  std::ostream& out_;
  std::vector<Level> stack_;
  bool done_ = false;
};

}  // namespace posefuse::apps
