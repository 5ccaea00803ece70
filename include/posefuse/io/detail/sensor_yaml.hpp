#pragma once
/// @file
/// The subset of YAML that sensor calibration files use (EuRoC `sensor.yaml`,
/// Kalibr and OpenCV-style files), read without a YAML library (not API):
/// `key: value` mappings nested by indentation, flow lists `[a, b]` over one
/// or several lines (nested flow lists are flattened), block lists (`- a`),
/// flow mappings `{k: v, ...}`, quoted scalars, `#` comments (at the start of
/// a line or after a space), `%YAML` / `---` / `...` lines, and tags such as
/// `!!opencv-matrix` (ignored). Anchors, aliases, multi-line scalars and
/// lists of mappings are not read: a line this reader cannot place is an
/// io_error naming file:line. Every value keeps its line for later errors.

#include <charconv>
#include <cmath>
#include <cstddef>
#include <filesystem>
#include <map>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>
#include <vector>

#include <posefuse/core/error.hpp>
#include <posefuse/io/detail/csv.hpp>
#include <posefuse/io/detail/line_reader.hpp>

namespace posefuse::detail::sensor_yaml {

/// One value: a scalar, a list of scalars or a mapping.
struct Value {
  std::size_t line = 0;                 ///< line of the key
  bool is_list = false, is_map = false;
  std::string scalar;                   ///< the text of a scalar (quotes kept)
  std::vector<std::string> items;       ///< list items (text)
  std::vector<std::size_t> item_lines;  ///< line of each item
  std::map<std::string, Value> children;  ///< mapping entries
};

/// The top-level mapping.
using Document = std::map<std::string, Value>;

/// A line without its comment, indentation and trailing spaces.
struct Line {
  std::size_t no = 0;
  std::size_t indent = 0;
  std::string text;
};

/// `text` without a `#` comment (a '#' at the start or after a space or tab,
/// outside quotes) and without trailing spaces.
template <class Lazy = void>
[[nodiscard]] std::string strip_comment(std::string_view text) {
  char quote = 0;
  std::size_t end = text.size();
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (quote != 0) {
      if (c == quote) quote = 0;
    } else if (c == '"' || c == '\'') {
      quote = c;
    } else if (c == '#' && (i == 0 || text[i - 1] == ' ' || text[i - 1] == '\t')) {
      end = i;
      break;
    }
  }
  std::string out(text.substr(0, end));
  while (!out.empty() && (out.back() == ' ' || out.back() == '\t')) out.pop_back();
  return out;
}

/// A scalar without its surrounding quotes.
[[nodiscard]] inline std::string unquote(std::string_view s) {
  s = trim_blanks(s);
  if (s.size() >= 2 && (s.front() == '"' || s.front() == '\'') && s.back() == s.front())
    return std::string(s.substr(1, s.size() - 2));
  return std::string(s);
}

/// `s` without a leading tag (`!!opencv-matrix`, `!foo`).
[[nodiscard]] inline std::string_view drop_tag(std::string_view s) {
  s = trim_blanks(s);
  if (!s.empty() && s.front() == '!') {
    const std::size_t sp = s.find_first_of(" \t");
    s = sp == std::string_view::npos ? std::string_view{} : trim_blanks(s.substr(sp));
  }
  return s;
}

/// Parses a list item or scalar as a finite double (YAML's `.nan`, `.inf`
/// and anything else not a plain decimal number are refused).
/// @throws posefuse::io_error naming file:line, the key and the item (0-based)
template <class Lazy = void>
[[nodiscard]] double parse_finite(std::string_view text, std::string_view key, std::size_t item,
                                  const std::filesystem::path& file, std::size_t line) {
  const std::string token = unquote(text);
  std::string_view digits = token;
  if (digits.size() > 1 && digits.front() == '+') digits.remove_prefix(1);
  double v = 0;
  const char* const end = digits.data() + digits.size();
  const auto [ptr, ec] = std::from_chars(digits.data(), end, v);
  const std::string where = std::string(key) + " item " + std::to_string(item + 1);
  if (ec != std::errc{} || ptr != end || digits.empty())
    throw io_error(file, line, where + ": cannot parse '" + token + "' as a number");
  if (!std::isfinite(v)) throw io_error(file, line, where + ": non-finite value '" + token + "'");
  return v;
}

/// Joins lines from `lines[i]` (starting at column `col`) until the bracket
/// opened there closes; returns the characters with their lines and advances
/// `i` past the last line used.
template <class Lazy = void>
[[nodiscard]] std::vector<std::pair<char, std::size_t>> gather_flow(const std::vector<Line>& lines,
                                                                    std::size_t& i, std::size_t col,
                                                                    const std::filesystem::path& file) {
  std::vector<std::pair<char, std::size_t>> chars;
  int depth = 0;
  char quote = 0;
  const std::size_t first = lines[i].no;
  for (std::size_t c = col;; c = 0) {
    const Line& L = lines[i];
    for (; c < L.text.size(); ++c) {
      const char ch = L.text[c];
      chars.emplace_back(ch, L.no);
      if (quote != 0) {
        if (ch == quote) quote = 0;
        continue;
      }
      if (ch == '"' || ch == '\'') quote = ch;
      if (ch == '[' || ch == '{') ++depth;
      if (ch == ']' || ch == '}') --depth;
      if (depth == 0) {
        if (c + 1 != L.text.size())
          throw io_error(file, L.no, "unexpected text after the closing bracket: '" +
                                         L.text.substr(c + 1) + "'");
        ++i;
        return chars;
      }
    }
    chars.emplace_back(' ', L.no);  // the line break separates tokens
    if (++i == lines.size())
      throw io_error(file, first, "the list or mapping opened here is not closed");
  }
}

/// Items of a flow list (nested lists flattened) from gathered characters.
template <class Lazy = void>
void flow_list_items(const std::vector<std::pair<char, std::size_t>>& chars, Value& v,
                     const std::filesystem::path& file) {
  std::string cur;
  std::size_t cur_line = 0;
  bool after_close = false;  // the last token was a ']' (a comma may follow)
  const auto flush = [&](std::size_t line, bool at_comma) {
    const std::string item(trim_blanks(cur));
    cur.clear();
    if (item.empty()) {
      if (at_comma && !after_close) throw io_error(file, line, "empty item in a list");
      return;
    }
    if (item.front() != '"' && item.front() != '\'' && item.find_first_of("{}:") != std::string::npos)
      throw io_error(file, cur_line, "list item '" + item + "' is not a single value");
    v.items.push_back(unquote(item));
    v.item_lines.push_back(cur_line);
  };
  char quote = 0;
  for (const auto& [ch, line] : chars) {
    if (quote != 0) {
      cur += ch;
      if (ch == quote) quote = 0;
      continue;
    }
    if (ch == '[' || ch == ']') {
      flush(line, false);
      after_close = ch == ']';
      continue;
    }
    if (ch == ',') {
      flush(line, true);
      after_close = false;
      continue;
    }
    if (ch == '"' || ch == '\'') quote = ch;
    if (ch != ' ' && ch != '\t' && trim_blanks(cur).empty()) cur_line = line;
    if (ch != ' ' && ch != '\t') after_close = false;
    cur += ch;
  }
}

/// Inserts `child` under `key`; a repeated key is an error naming both lines.
template <class Lazy = void>
void insert_unique(std::map<std::string, Value>& m, const std::string& key, const Value& child,
                   const std::filesystem::path& file) {
  const auto [it, inserted] = m.emplace(key, child);
  if (!inserted)
    throw io_error(file, child.line,
                   "key '" + key + "' repeats the one on line " + std::to_string(it->second.line));
}

/// Entries of a flow mapping `{k: v, k: [a, b]}` from gathered characters
/// (values are scalars or flow lists).
template <class Lazy = void>
void flow_map_entries(const std::vector<std::pair<char, std::size_t>>& chars, Value& v,
                      const std::filesystem::path& file) {
  using Chars = std::vector<std::pair<char, std::size_t>>;
  std::vector<Chars> pieces(1);
  int depth = 0;
  char quote = 0;
  for (std::size_t c = 1; c + 1 < chars.size(); ++c) {  // inside the outer braces
    const char ch = chars[c].first;
    if (quote != 0) {
      if (ch == quote) quote = 0;
    } else if (ch == '"' || ch == '\'') {
      quote = ch;
    } else if (ch == '[') {
      ++depth;
    } else if (ch == ']') {
      --depth;
    } else if (ch == '{') {
      throw io_error(file, chars[c].second, "nested mappings inside {...} are not read");
    } else if (ch == ',' && depth == 0) {
      pieces.emplace_back();
      continue;
    }
    pieces.back().push_back(chars[c]);
  }
  for (const Chars& p : pieces) {
    std::size_t k = 0;
    while (k < p.size() && (p[k].first == ' ' || p[k].first == '\t')) ++k;
    if (k == p.size()) continue;
    const std::size_t line = p[k].second;
    std::size_t colon = k;
    while (colon < p.size() && p[colon].first != ':') ++colon;
    if (colon == p.size()) throw io_error(file, line, "expected 'key: value' inside {...}");
    std::string key;
    for (std::size_t j = k; j < colon; ++j) key += p[j].first;
    Value child;
    child.line = line;
    std::size_t j = colon + 1;
    while (j < p.size() && (p[j].first == ' ' || p[j].first == '\t')) ++j;
    if (j < p.size() && p[j].first == '[') {
      child.is_list = true;
      flow_list_items(Chars(p.begin() + std::ptrdiff_t(j), p.end()), child, file);
    } else {
      std::string text;
      for (; j < p.size(); ++j) text += p[j].first;
      child.scalar = std::string(drop_tag(text));
    }
    insert_unique(v.children, unquote(key), child, file);
  }
}

template <class Lazy = void>
void parse_block(const std::vector<Line>& lines, std::size_t& i, std::size_t indent,
                 std::map<std::string, Value>& out, const std::filesystem::path& file);

/// The value after `key:` on line `lines[i]` (its text from column
/// `rest_col`); advances `i` past the lines it used.
template <class Lazy = void>
void parse_value(const std::vector<Line>& lines, std::size_t& i, std::size_t indent,
                 std::size_t rest_col, Value& v, const std::filesystem::path& file) {
  const Line& L = lines[i];
  const std::string_view rest = drop_tag(std::string_view(L.text).substr(rest_col));
  if (rest.empty()) {  // a block below, or nothing (null)
    ++i;
    if (i < lines.size() && lines[i].indent >= indent && lines[i].text.front() == '-' &&
        (lines[i].text.size() == 1 || lines[i].text[1] == ' ')) {
      v.is_list = true;
      const std::size_t list_indent = lines[i].indent;
      while (i < lines.size() && lines[i].indent == list_indent && lines[i].text.front() == '-') {
        const std::string item(trim_blanks(std::string_view(lines[i].text).substr(1)));
        if (item.empty() || item.front() == '[' || item.front() == '{' ||
            (item.find(": ") != std::string::npos && item.front() != '"' && item.front() != '\''))
          throw io_error(file, lines[i].no, "block list items must be single values");
        v.items.push_back(unquote(item));
        v.item_lines.push_back(lines[i].no);
        ++i;
      }
    } else if (i < lines.size() && lines[i].indent > indent) {
      v.is_map = true;
      parse_block(lines, i, lines[i].indent, v.children, file);
    }
    return;
  }
  const std::size_t start = L.text.size() - rest.size();  // L.text has no trailing spaces
  if (rest.front() == '[') {
    v.is_list = true;
    flow_list_items(gather_flow(lines, i, start, file), v, file);
  } else if (rest.front() == '{') {
    v.is_map = true;
    flow_map_entries(gather_flow(lines, i, start, file), v, file);
  } else {
    v.scalar = std::string(rest);
    ++i;
  }
}

/// Parses the `key: value` lines of one indentation level.
template <class Lazy>
void parse_block(const std::vector<Line>& lines, std::size_t& i, std::size_t indent,
                 std::map<std::string, Value>& out, const std::filesystem::path& file) {
  while (i < lines.size()) {
    const Line& L = lines[i];
    if (L.indent < indent) return;
    if (L.indent > indent)
      throw io_error(file, L.no, "unexpected indentation (expected a key at column " +
                                     std::to_string(indent + 1) + ")");
    // The key ends at the first ':' followed by a space or the end of the line.
    std::size_t colon = std::string::npos;
    char quote = 0;
    for (std::size_t c = 0; c < L.text.size(); ++c) {
      const char ch = L.text[c];
      if (quote != 0) {
        if (ch == quote) quote = 0;
        continue;
      }
      if (ch == '"' || ch == '\'') quote = ch;
      else if (ch == ':' && (c + 1 == L.text.size() || L.text[c + 1] == ' ' || L.text[c + 1] == '\t')) {
        colon = c;
        break;
      }
    }
    if (colon == std::string::npos || colon == 0)
      throw io_error(file, L.no, "expected 'key: value', found '" + L.text + "'");
    const std::string key = unquote(std::string_view(L.text).substr(0, colon));
    Value v;
    v.line = L.no;
    parse_value(lines, i, indent, colon + 1, v, file);
    insert_unique(out, key, v, file);
  }
}

/// Reads `file` into its top-level mapping.
/// @throws posefuse::io_error (file:line) for a line this subset cannot read
template <class Lazy = void>
[[nodiscard]] Document parse(const std::filesystem::path& file) {
  LineReader reader(file);
  std::vector<Line> lines;
  std::string raw;
  while (reader.next(raw)) {
    const std::size_t no = reader.line_no();
    if (raw.rfind("%", 0) == 0 || raw == "---" || raw == "...") continue;
    std::size_t indent = 0;
    while (indent < raw.size() && (raw[indent] == ' ' || raw[indent] == '\t')) {
      if (raw[indent] == '\t')
        throw io_error(file, no, "a tab in the indentation (YAML indents with spaces)");
      ++indent;
    }
    std::string text = strip_comment(std::string_view(raw).substr(indent));
    if (text.empty()) continue;
    lines.push_back(Line{no, indent, std::move(text)});
  }
  Document doc;
  if (lines.empty()) throw io_error(file, "no 'key: value' lines");
  std::size_t i = 0;
  parse_block(lines, i, lines.front().indent, doc, file);
  if (i < lines.size())
    throw io_error(file, lines[i].no, "unexpected indentation (less than the first key's)");
  return doc;
}

}  // namespace posefuse::detail::sensor_yaml
