#pragma once
// Runs an example program for end-to-end tests: captures exit status, stdout
// and stderr; finds examples in the build tree (POSEFUSE_EXAMPLES_DIR).
// Also a strict JSON reader (RFC 8259) to check the programs' --json output.
#include <charconv>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <sys/wait.h>
#include <variant>
#include <vector>

#include "support/temp_dir.hpp"

namespace posefuse::test {

struct Run {
  int status = -1;
  std::string out, err;
};

inline std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

/// Runs `exe args` through the shell, with stdout/stderr captured in `dir`.
inline Run run(const std::filesystem::path& exe, const std::string& args, const TempDir& dir) {
  const auto out = dir.path() / "stdout.txt", err = dir.path() / "stderr.txt";
  const std::string cmd =
      "'" + exe.string() + "' " + args + " >'" + out.string() + "' 2>'" + err.string() + "'";
  const int raw = std::system(cmd.c_str());
  Run r;
  r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  r.out = slurp(out);
  r.err = slurp(err);
  return r;
}

/// Number of '\n' in `s`.
inline std::size_t count_lines(const std::string& s) {
  std::size_t n = 0;
  for (const char c : s) n += c == '\n' ? 1 : 0;
  return n;
}

/// A parsed JSON value (null, bool, number, string, array or object).
class Json {
 public:
  using Array = std::vector<Json>;
  using Object = std::map<std::string, Json>;

  /// Parses `text` strictly: exactly one value, optional surrounding
  /// whitespace; RFC 8259 grammar (no NaN, no trailing commas, no control
  /// characters in strings, no duplicate keys).
  /// @throws std::runtime_error naming the offset of the first error
  static Json parse(std::string_view text) {
    Reader r{text, 0};
    r.ws();
    Json v = r.value(0);
    r.ws();
    if (r.i != text.size()) r.fail("text after the value");
    return v;
  }

  bool is_null() const { return std::holds_alternative<std::monostate>(v_); }
  bool is_number() const { return std::holds_alternative<double>(v_); }
  bool is_string() const { return std::holds_alternative<std::string>(v_); }
  bool is_array() const { return std::holds_alternative<Array>(v_); }
  bool is_object() const { return std::holds_alternative<Object>(v_); }
  bool boolean() const { return get<bool>("a bool"); }
  double number() const { return get<double>("a number"); }
  const std::string& string() const { return get<std::string>("a string"); }
  const Array& array() const { return get<Array>("an array"); }
  const Object& object() const { return get<Object>("an object"); }
  /// Member `key` of an object.
  /// @throws std::runtime_error when this is not an object or has no such member
  const Json& operator[](const std::string& key) const {
    const Object& o = object();
    const auto it = o.find(key);
    if (it == o.end()) throw std::runtime_error("JSON: no member '" + key + "'");
    return it->second;
  }
  /// Element `k` of an array.
  const Json& operator[](std::size_t k) const {
    const Array& a = array();
    if (k >= a.size()) throw std::runtime_error("JSON: index out of range");
    return a[k];
  }
  bool has(const std::string& key) const { return object().count(key) > 0; }

 private:
  template <class T>
  const T& get(const char* what) const {
    if (const T* p = std::get_if<T>(&v_)) return *p;
    throw std::runtime_error(std::string("JSON: value is not ") + what);
  }

  struct Reader {
    std::string_view s;
    std::size_t i;
    [[noreturn]] void fail(const std::string& why) const {
      throw std::runtime_error("JSON: " + why + " at offset " + std::to_string(i));
    }
    void ws() {
      while (i < s.size() && (s[i] == ' ' || s[i] == '\t' || s[i] == '\n' || s[i] == '\r')) ++i;
    }
    bool eat(char c) {
      if (i < s.size() && s[i] == c) {
        ++i;
        return true;
      }
      return false;
    }
    void expect(char c) {
      if (!eat(c)) fail(std::string("expected '") + c + "'");
    }
    Json value(int depth) {
      if (depth > 64) fail("nested too deeply");
      if (i >= s.size()) fail("unexpected end");
      Json j;
      const char c = s[i];
      if (c == '{') {
        ++i;
        Object o;
        ws();
        if (!eat('}')) {
          do {
            ws();
            if (i >= s.size() || s[i] != '"') fail("expected a member name");
            std::string k = str();
            ws();
            expect(':');
            ws();
            Json v = value(depth + 1);
            if (!o.emplace(std::move(k), std::move(v)).second) fail("duplicate member name");
            ws();
          } while (eat(','));
          expect('}');
        }
        j.v_ = std::move(o);
      } else if (c == '[') {
        ++i;
        Array a;
        ws();
        if (!eat(']')) {
          do {
            ws();
            a.push_back(value(depth + 1));
            ws();
          } while (eat(','));
          expect(']');
        }
        j.v_ = std::move(a);
      } else if (c == '"') {
        j.v_ = str();
      } else if (s.substr(i, 4) == "true") {
        i += 4;
        j.v_ = true;
      } else if (s.substr(i, 5) == "false") {
        i += 5;
        j.v_ = false;
      } else if (s.substr(i, 4) == "null") {
        i += 4;
      } else {
        j.v_ = num();
      }
      return j;
    }
    double num() {
      const std::size_t start = i;
      eat('-');
      if (eat('0')) {
      } else if (i < s.size() && s[i] >= '1' && s[i] <= '9') {
        while (i < s.size() && s[i] >= '0' && s[i] <= '9') ++i;
      } else {
        fail("expected a value");
      }
      const auto digits = [&] {
        const std::size_t d = i;
        while (i < s.size() && s[i] >= '0' && s[i] <= '9') ++i;
        if (i == d) fail("expected a digit");
      };
      if (eat('.')) digits();
      if (eat('e') || eat('E')) {
        if (!eat('+')) eat('-');
        digits();
      }
      double v = 0;
      const auto [p, ec] = std::from_chars(s.data() + start, s.data() + i, v);
      if (ec != std::errc{} || p != s.data() + i) fail("number out of range");
      return v;
    }
    std::string str() {
      expect('"');
      std::string o;
      while (true) {
        if (i >= s.size()) fail("unterminated string");
        const unsigned char c = static_cast<unsigned char>(s[i++]);
        if (c == '"') return o;
        if (c < 0x20) fail("control character in a string");
        if (c != '\\') {
          o += static_cast<char>(c);
          continue;
        }
        if (i >= s.size()) fail("unterminated escape");
        const char e = s[i++];
        switch (e) {
          case '"': o += '"'; break;
          case '\\': o += '\\'; break;
          case '/': o += '/'; break;
          case 'b': o += '\b'; break;
          case 'f': o += '\f'; break;
          case 'n': o += '\n'; break;
          case 'r': o += '\r'; break;
          case 't': o += '\t'; break;
          case 'u': {
            if (i + 4 > s.size()) fail("short \\u escape");
            unsigned cp = 0;
            const auto [p, ec] = std::from_chars(s.data() + i, s.data() + i + 4, cp, 16);
            if (ec != std::errc{} || p != s.data() + i + 4) fail("bad \\u escape");
            i += 4;
            if (cp >= 0xD800 && cp <= 0xDFFF) fail("surrogate escapes are not expected here");
            if (cp < 0x80) {
              o += static_cast<char>(cp);
            } else if (cp < 0x800) {
              o += static_cast<char>(0xC0 | (cp >> 6));
              o += static_cast<char>(0x80 | (cp & 0x3F));
            } else {
              o += static_cast<char>(0xE0 | (cp >> 12));
              o += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
              o += static_cast<char>(0x80 | (cp & 0x3F));
            }
            break;
          }
          default: fail("bad escape");
        }
      }
    }
  };

  std::variant<std::monostate, bool, double, std::string, Array, Object> v_;
};

/// The path of a built example, or an empty path when it was not built.
inline std::filesystem::path example(const std::string& name) {
  const std::filesystem::path exe = std::filesystem::path(POSEFUSE_EXAMPLES_DIR) / name;
  return std::filesystem::exists(exe) ? exe : std::filesystem::path{};
}

}  // namespace posefuse::test

/// Skips the current test case visibly when an example program is not built.
#define POSEFUSE_REQUIRE_EXAMPLE(var, name)                                                   \
  const std::filesystem::path var = ::posefuse::test::example(name);                          \
  if (var.empty()) {                                                                          \
    WARN("SKIPPED: example '" << (name) << "' not built (POSEFUSE_BUILD_EXAMPLES=ON)");      \
    return;                                                                                   \
  }
