#pragma once
/// @file
/// A strict JSON reader (RFC 8259) for the example programs (compare_results
/// reads the files evaluate_trajectory --save-results writes) and for the
/// tests that check the programs' --json output.

#include <charconv>
#include <map>
#include <stdexcept>
#include <string>
#include <string_view>
#include <system_error>
#include <variant>
#include <vector>

namespace posefuse::apps {

/// A parsed JSON value (null, bool, number, string, array or object).
class JsonValue {
 public:
  using Array = std::vector<JsonValue>;
  using Object = std::map<std::string, JsonValue>;

  /// Parses `text` strictly: exactly one value, optional surrounding
  /// whitespace; RFC 8259 grammar (no NaN, no trailing commas, no control
  /// characters in strings, no duplicate keys).
  /// @throws std::runtime_error naming the offset of the first error
  static JsonValue parse(std::string_view text) {
    Reader r{text, 0};
    r.ws();
    JsonValue v = r.value(0);
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
  const JsonValue& operator[](const std::string& key) const {
    const Object& o = object();
    const auto it = o.find(key);
    if (it == o.end()) throw std::runtime_error("JSON: no member '" + key + "'");
    return it->second;
  }
  /// Element `k` of an array.
  const JsonValue& operator[](std::size_t k) const {
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
    JsonValue value(int depth) {
      if (depth > 64) fail("nested too deeply");
      if (i >= s.size()) fail("unexpected end");
      JsonValue j;
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
            JsonValue v = value(depth + 1);
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

}  // namespace posefuse::apps
