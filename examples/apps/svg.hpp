#pragma once
/// @file
/// A small SVG writer for the example programs' plots: a Document in pixel
/// coordinates (y down) and Plots in data coordinates (y up) with axes, ticks,
/// units, a title and a legend.
///
///     apps::svg::Plot paths("road-plane paths");
///     paths.x_axis("x", "m").y_axis("z", "m").equal_aspect();
///     paths.line("ground truth", truth_xy, {"#000000", 2.0});
///     paths.line("raw", raw_xy, {"#d62728", 1.0});
///     apps::svg::Document doc(520, 480);
///     doc.plot(paths, {0, 0, 520, 480});
///     const std::string text = doc.str();
///
/// Every number written is checked: a non-finite coordinate throws
/// posefuse::invalid_argument (naming the series) instead of writing "nan"
/// into the file. Text is escaped for XML (& < > " '), control characters
/// and invalid UTF-8 become U+FFFD.

#include <Eigen/Core>
#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <posefuse/core/error.hpp>

namespace posefuse::apps::svg {

/// A point: data units in a Plot, pixels (y down) in a Document.
struct Point {
  double x = 0;
  double y = 0;
};

/// A rectangle in pixels: top-left corner and size.
struct Rect {
  double x = 0;
  double y = 0;
  double width = 0;
  double height = 0;
};

/// How a line is drawn.
struct Stroke {
  std::string colour = "#000000";  ///< any SVG colour
  double width = 1.0;              ///< px
  std::string dash;                ///< stroke-dasharray ("6,3"); empty: solid
};

/// Shape of a marker.
enum class Marker { kCircle, kSquare, kCross };

/// Horizontal anchor of a text.
enum class Anchor { kStart, kMiddle, kEnd };

namespace detail {

/// Length of the valid UTF-8 sequence at s[i], or 0 when it is not one.
[[nodiscard]] inline std::size_t svg_utf8_length(std::string_view s, std::size_t i) noexcept {
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
      (cp >= 0xD800 && cp <= 0xDFFF) || cp == 0xFFFE || cp == 0xFFFF)
    return 0;
  return n;
}

/// Fixed-point text with `decimals` digits (std::to_chars, locale-free).
[[nodiscard]] inline std::string fixed(double v, int decimals) {
  char buf[400];
  const auto [ptr, ec] = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::fixed, decimals);
  if (ec != std::errc{}) throw invalid_argument("svg: number too large to write");
  return std::string(buf, ptr);
}

}  // namespace detail

/// `text` escaped for SVG text and attribute values.
[[nodiscard]] inline std::string escape(std::string_view text) {
  std::string o;
  for (std::size_t i = 0; i < text.size();) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    if (c >= 0x80) {
      const std::size_t n = detail::svg_utf8_length(text, i);
      if (n == 0) {
        o += "\xEF\xBF\xBD";  // U+FFFD
        ++i;
      } else {
        o.append(text.substr(i, n));
        i += n;
      }
      continue;
    }
    switch (c) {
      case '&': o += "&amp;"; break;
      case '<': o += "&lt;"; break;
      case '>': o += "&gt;"; break;
      case '"': o += "&quot;"; break;
      case '\'': o += "&apos;"; break;
      default:
        if (c < 0x20 || c == 0x7F) o += "\xEF\xBF\xBD";  // not allowed in XML 1.0
        else o += static_cast<char>(c);
    }
    ++i;
  }
  return o;
}

/// A pixel coordinate or length as SVG text (2 decimals).
/// @throws posefuse::invalid_argument when `v` is not finite
[[nodiscard]] inline std::string coordinate(double v) {
  if (!std::isfinite(v)) throw invalid_argument("svg: non-finite coordinate");
  const std::string s = detail::fixed(v, 2);
  return s == "-0.00" ? std::string("0.00") : s;
}

class Document;

/// A plot in data coordinates: series, axes with units, title and legend,
/// drawn into a rectangle of a Document by Document::plot.
class Plot {
 public:
  /// @param[in] title drawn above the plot area
  explicit Plot(std::string title = {}) : title_(std::move(title)) {}

  /// Label and unit of the horizontal axis, drawn as "label (unit)".
  Plot& x_axis(std::string label, std::string unit = {}) {
    x_label_ = axis_text(std::move(label), unit);
    return *this;
  }
  /// Label and unit of the vertical axis.
  Plot& y_axis(std::string label, std::string unit = {}) {
    y_label_ = axis_text(std::move(label), unit);
    return *this;
  }
  /// One data unit is as long on both axes (for paths in metres).
  Plot& equal_aspect(bool on = true) {
    equal_aspect_ = on;
    return *this;
  }
  /// Extends the axes to contain `p` (e.g. the origin of a variance axis).
  /// @throws posefuse::invalid_argument when `p` is not finite
  Plot& include(Point p) {
    check("include", p, 0);
    extra_.push_back(p);
    return *this;
  }

  /// A polyline series with a legend entry (an empty `legend`: none).
  /// @throws posefuse::invalid_argument when a point is not finite
  Plot& line(std::string legend, std::vector<Point> points, Stroke stroke) {
    for (std::size_t k = 0; k < points.size(); ++k) check(legend, points[k], k);
    series_.push_back({std::move(legend), std::move(points), std::move(stroke), false, Marker::kCircle});
    return *this;
  }
  /// A polyline series from 2-D vectors (x, y). (With a braced list of
  /// points, name the type: `std::vector<svg::Point>{...}`.)
  Plot& line(std::string legend, const std::vector<Eigen::Vector2d>& points, Stroke stroke) {
    std::vector<Point> p;
    p.reserve(points.size());
    for (const Eigen::Vector2d& v : points) p.push_back({v.x(), v.y()});
    return line(std::move(legend), std::move(p), std::move(stroke));
  }
  /// Markers at `points`, in `stroke.colour`, `size` px across.
  /// @throws posefuse::invalid_argument when a point is not finite
  Plot& markers(std::string legend, std::vector<Point> points, Marker shape, Stroke stroke,
                double size = 8) {
    for (std::size_t k = 0; k < points.size(); ++k) check(legend, points[k], k);
    stroke.width = size;
    series_.push_back({std::move(legend), std::move(points), std::move(stroke), true, shape});
    return *this;
  }

  /// Number of legend entries (series with a non-empty legend).
  [[nodiscard]] std::size_t legend_entries() const noexcept {
    return static_cast<std::size_t>(std::count_if(
        series_.begin(), series_.end(), [](const Series& s) { return !s.legend.empty(); }));
  }

 private:
  friend class Document;
  struct Series {
    std::string legend;
    std::vector<Point> points;
    Stroke stroke;
    bool is_markers;
    Marker shape;
  };

  static std::string axis_text(std::string label, const std::string& unit) {
    return unit.empty() ? label : label + " (" + unit + ")";
  }
  static void check(const std::string& what, Point p, std::size_t k) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y))
      throw invalid_argument("svg: '" + what + "' has a non-finite point (index " +
                             std::to_string(k) + ")");
  }

  std::string title_, x_label_, y_label_;
  bool equal_aspect_ = false;
  std::vector<Point> extra_;
  std::vector<Series> series_;
};

/// An SVG document in pixel coordinates (origin top-left, y down), white background.
class Document {
 public:
  /// @param[in] width, height size in px
  /// @throws posefuse::invalid_argument unless both are finite and > 0
  Document(double width, double height) {
    if (!(width > 0 && height > 0 && std::isfinite(width) && std::isfinite(height)))
      throw invalid_argument("svg: the document size must be finite and > 0");
    head_ = "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" + coordinate(width) +
            "\" height=\"" + coordinate(height) + "\" viewBox=\"0 0 " + coordinate(width) + " " +
            coordinate(height) + "\" font-family=\"sans-serif\" font-size=\"12\">\n" +
            "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  }

  /// A straight line.
  Document& line(Point a, Point b, const Stroke& s) {
    body_ += "<line x1=\"" + coordinate(a.x) + "\" y1=\"" + coordinate(a.y) + "\" x2=\"" +
             coordinate(b.x) + "\" y2=\"" + coordinate(b.y) + "\"" + stroke_attributes(s) + "/>\n";
    return *this;
  }

  /// A polyline (nothing for fewer than one point).
  Document& polyline(const std::vector<Point>& points, const Stroke& s) {
    if (points.empty()) return *this;
    body_ += "<polyline fill=\"none\"" + stroke_attributes(s) + " points=\"";
    for (std::size_t k = 0; k < points.size(); ++k) {
      if (k) body_ += ' ';
      body_ += coordinate(points[k].x) + "," + coordinate(points[k].y);
    }
    body_ += "\"/>\n";
    return *this;
  }

  /// A rectangle outline (`fill` "none" for none).
  Document& rect(Rect r, const std::string& fill, const Stroke& s) {
    body_ += "<rect x=\"" + coordinate(r.x) + "\" y=\"" + coordinate(r.y) + "\" width=\"" +
             coordinate(r.width) + "\" height=\"" + coordinate(r.height) + "\" fill=\"" +
             escape(fill) + "\"" + stroke_attributes(s) + "/>\n";
    return *this;
  }

  /// A marker centred on `p`, `size` px across, in `colour`.
  Document& marker(Point p, Marker shape, double size, const std::string& colour) {
    const double h = 0.5 * size;
    switch (shape) {
      case Marker::kCircle:
        body_ += "<circle cx=\"" + coordinate(p.x) + "\" cy=\"" + coordinate(p.y) + "\" r=\"" +
                 coordinate(h) + "\" fill=\"" + escape(colour) + "\"/>\n";
        break;
      case Marker::kSquare:
        body_ += "<rect x=\"" + coordinate(p.x - h) + "\" y=\"" + coordinate(p.y - h) +
                 "\" width=\"" + coordinate(size) + "\" height=\"" + coordinate(size) +
                 "\" fill=\"" + escape(colour) + "\"/>\n";
        break;
      case Marker::kCross:
        line({p.x - h, p.y - h}, {p.x + h, p.y + h}, {colour, 2.0, {}});
        line({p.x - h, p.y + h}, {p.x + h, p.y - h}, {colour, 2.0, {}});
        break;
    }
    return *this;
  }

  /// Text with its baseline at `p` (escaped); `rotate_deg` turns it about `p`.
  Document& text(Point p, std::string_view content, double size = 12, Anchor anchor = Anchor::kStart,
                 double rotate_deg = 0) {
    body_ += "<text x=\"" + coordinate(p.x) + "\" y=\"" + coordinate(p.y) + "\" font-size=\"" +
             coordinate(size) + "\"";
    if (anchor != Anchor::kStart)
      body_ += std::string(" text-anchor=\"") + (anchor == Anchor::kMiddle ? "middle" : "end") + "\"";
    if (rotate_deg != 0)
      body_ += " transform=\"rotate(" + coordinate(rotate_deg) + " " + coordinate(p.x) + " " +
               coordinate(p.y) + ")\"";
    body_ += ">" + escape(content) + "</text>\n";
    return *this;
  }

  /// Draws `plot` into `area`: title on top, the plot box with grid, ticks
  /// and axis labels, the series, and the legend below the x axis.
  /// @throws posefuse::invalid_argument when the area is too small for the plot
  Document& plot(const Plot& plot, Rect area) {
    constexpr double kTop = 30, kLeft = 70, kRight = 16, kBottom = 44, kRow = 18;
    const std::size_t entries = plot.legend_entries();
    const Rect box{area.x + kLeft, area.y + kTop, area.width - kLeft - kRight,
                   area.height - kTop - kBottom - kRow * double(entries) - (entries ? 6 : 0)};
    if (!(box.width > 20 && box.height > 20))
      throw invalid_argument("svg: the area is too small for the plot");

    // Data range, padded by 3 %; a zero span is widened to +-1 unit.
    constexpr double kInf = std::numeric_limits<double>::infinity();
    double x0 = kInf, x1 = -kInf, y0 = kInf, y1 = -kInf;
    const auto grow = [&](Point p) {
      x0 = std::min(x0, p.x), x1 = std::max(x1, p.x);
      y0 = std::min(y0, p.y), y1 = std::max(y1, p.y);
    };
    for (const auto& s : plot.series_)
      for (const Point& p : s.points) grow(p);
    for (const Point& p : plot.extra_) grow(p);
    if (!(x0 <= x1)) x0 = 0, x1 = 1, y0 = 0, y1 = 1;  // nothing to draw
    const auto widen = [](double& lo, double& hi) {
      if (hi - lo <= 0) {
        lo -= 1;
        hi += 1;
      } else {
        const double pad = 0.03 * (hi - lo);
        lo -= pad;
        hi += pad;
      }
    };
    widen(x0, x1);
    widen(y0, y1);
    if (plot.equal_aspect_) {  // one scale for both axes, data centred
      const double s = std::min(box.width / (x1 - x0), box.height / (y1 - y0));
      const double cx = 0.5 * (x0 + x1), cy = 0.5 * (y0 + y1);
      x0 = cx - 0.5 * box.width / s, x1 = cx + 0.5 * box.width / s;
      y0 = cy - 0.5 * box.height / s, y1 = cy + 0.5 * box.height / s;
    }
    if (!std::isfinite(x1 - x0) || !std::isfinite(y1 - y0))
      throw invalid_argument("svg: the data range is too large to plot");
    const auto map = [&](Point p) -> Point {
      return {box.x + (p.x - x0) / (x1 - x0) * box.width,
              box.y + box.height - (p.y - y0) / (y1 - y0) * box.height};
    };

    if (!plot.title_.empty()) text({box.x, area.y + 18}, plot.title_, 14);
    const Stroke grid{"#e6e6e6", 1.0, {}}, frame{"#808080", 1.0, {}};
    for (const int axis : {0, 1}) {
      const double lo = axis == 0 ? x0 : y0, hi = axis == 0 ? x1 : y1;
      const double step = nice_step(hi - lo);
      const int decimals = std::max(0, -static_cast<int>(std::floor(std::log10(step) + 1e-9)));
      const double first = std::ceil(lo / step - 1e-9);
      for (int k = 0; first + k <= hi / step + 1e-9 && k < 100; ++k) {
        const double v = (first + k) * step;
        const std::string label = detail::fixed(std::abs(v) < 1e-9 * step ? 0.0 : v, decimals);
        if (axis == 0) {
          const double px = map({v, y0}).x;
          line({px, box.y}, {px, box.y + box.height}, grid);
          text({px, box.y + box.height + 15}, label, 11, Anchor::kMiddle);
        } else {
          const double py = map({x0, v}).y;
          line({box.x, py}, {box.x + box.width, py}, grid);
          text({box.x - 5, py + 4}, label, 11, Anchor::kEnd);
        }
      }
    }
    rect(box, "none", frame);
    if (!plot.x_label_.empty())
      text({box.x + 0.5 * box.width, box.y + box.height + 34}, plot.x_label_, 12, Anchor::kMiddle);
    if (!plot.y_label_.empty())
      text({area.x + 16, box.y + 0.5 * box.height}, plot.y_label_, 12, Anchor::kMiddle, -90);

    for (const auto& s : plot.series_) {
      if (s.is_markers) {
        for (const Point& p : s.points) marker(map(p), s.shape, s.stroke.width, s.stroke.colour);
      } else {
        std::vector<Point> px;
        px.reserve(s.points.size());
        for (const Point& p : s.points) px.push_back(map(p));
        polyline(px, s.stroke);
      }
    }

    double ly = box.y + box.height + kBottom + 6;
    for (const auto& s : plot.series_) {
      if (s.legend.empty()) continue;
      if (s.is_markers) marker({box.x + 12, ly - 4}, s.shape, s.stroke.width, s.stroke.colour);
      else line({box.x, ly - 4}, {box.x + 24, ly - 4}, {s.stroke.colour, std::max(2.0, s.stroke.width), s.stroke.dash});
      text({box.x + 32, ly}, s.legend, 12);
      ly += kRow;
    }
    return *this;
  }

  /// The complete SVG text.
  [[nodiscard]] std::string str() const { return head_ + body_ + "</svg>\n"; }

 private:
  /// A 1, 2 or 5 times a power of ten giving about six ticks over `span`.
  static double nice_step(double span) {
    const double raw = span / 6.0;
    const double mag = std::pow(10.0, std::floor(std::log10(raw)));
    const double r = raw / mag;
    return (r < 1.5 ? 1.0 : r < 3.0 ? 2.0 : r < 7.0 ? 5.0 : 10.0) * mag;
  }

  static std::string stroke_attributes(const Stroke& s) {
    std::string a = " stroke=\"" + escape(s.colour) + "\" stroke-width=\"" + coordinate(s.width) + "\"";
    if (!s.dash.empty()) a += " stroke-dasharray=\"" + escape(s.dash) + "\"";
    return a;
  }

  std::string head_, body_;
};

}  // namespace posefuse::apps::svg
