#pragma once
// A strict well-formedness check for the XML the example programs write
// (SVG): one root element, every tag closed in order, attribute values
// quoted, no attribute twice, only the five predefined entities or numeric
// character references, no stray '<' or '&' in text. It returns the first
// problem found (empty when the document is well formed). Not a validating
// parser: DTDs, CDATA sections and processing instructions other than the
// XML declaration are reported as errors, since our writers never emit them.
#include <cctype>
#include <set>
#include <string>
#include <string_view>
#include <vector>

namespace posefuse::test {

inline std::string xml_problem(std::string_view s) {
  std::vector<std::string> open;
  std::size_t i = 0, roots = 0;
  const auto is_name = [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == ':' || c == '.';
  };
  const auto check_entities = [](std::string_view text) -> std::string {
    for (std::size_t k = 0; k < text.size(); ++k) {
      if (text[k] == '<') return "'<' in text or attribute";
      if (text[k] != '&') continue;
      const std::size_t end = text.find(';', k);
      if (end == std::string_view::npos) return "unterminated entity";
      const std::string_view e = text.substr(k + 1, end - k - 1);
      static const std::set<std::string_view> named{"amp", "lt", "gt", "quot", "apos"};
      const bool numeric = e.size() > 1 && e[0] == '#';
      if (!named.count(e) && !numeric) return "unknown entity &" + std::string(e) + ";";
      k = end;
    }
    return {};
  };
  if (s.substr(0, 5) == "<?xml") {
    i = s.find("?>");
    if (i == std::string_view::npos) return "unterminated XML declaration";
    i += 2;
  }
  while (i < s.size()) {
    const std::size_t lt = s.find('<', i);
    const std::string_view text = s.substr(i, lt == std::string_view::npos ? s.size() - i : lt - i);
    if (const std::string e = check_entities(text); !e.empty()) return e;
    if (open.empty() && text.find_first_not_of(" \t\r\n") != std::string_view::npos)
      return "text outside the root element";
    if (lt == std::string_view::npos) break;
    i = lt + 1;
    if (s.substr(i, 3) == "!--") {
      const std::size_t end = s.find("-->", i);
      if (end == std::string_view::npos) return "unterminated comment";
      i = end + 3;
      continue;
    }
    const bool closing = i < s.size() && s[i] == '/';
    if (closing) ++i;
    const std::size_t name_start = i;
    while (i < s.size() && is_name(s[i])) ++i;
    const std::string name(s.substr(name_start, i - name_start));
    if (name.empty()) return "a tag without a name";
    if (closing) {
      while (i < s.size() && std::isspace(static_cast<unsigned char>(s[i]))) ++i;
      if (i >= s.size() || s[i] != '>') return "malformed closing tag </" + name;
      if (open.empty() || open.back() != name) return "</" + name + "> does not close the open element";
      open.pop_back();
      ++i;
      continue;
    }
    std::set<std::string> attributes;
    for (;;) {
      while (i < s.size() && std::isspace(static_cast<unsigned char>(s[i]))) ++i;
      if (i >= s.size()) return "unterminated tag <" + name;
      if (s[i] == '>' || s.substr(i, 2) == "/>") break;
      const std::size_t a = i;
      while (i < s.size() && is_name(s[i])) ++i;
      const std::string attribute(s.substr(a, i - a));
      if (attribute.empty()) return "bad character in tag <" + name;
      if (!attributes.insert(attribute).second) return "attribute " + attribute + " twice in <" + name;
      if (i >= s.size() || s[i] != '=') return "attribute " + attribute + " without a value";
      ++i;
      if (i >= s.size() || (s[i] != '"' && s[i] != '\'')) return "unquoted value of " + attribute;
      const char q = s[i++];
      const std::size_t end = s.find(q, i);
      if (end == std::string_view::npos) return "unterminated value of " + attribute;
      if (const std::string e = check_entities(s.substr(i, end - i)); !e.empty()) return e;
      i = end + 1;
    }
    const bool empty_element = s[i] == '/';
    i += empty_element ? 2 : 1;
    if (open.empty() && ++roots > 1) return "more than one root element";
    if (!empty_element) open.push_back(name);
  }
  if (!open.empty()) return "<" + open.back() + "> is never closed";
  if (roots != 1) return "no root element";
  return {};
}

}  // namespace posefuse::test
