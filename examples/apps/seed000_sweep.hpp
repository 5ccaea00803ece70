#pragma once
/// @file
/// The sensitivity study of orb_trajectory_correction (`--sweep`): the
/// planar RMSE of each corrector over a log-spaced grid of its process x
/// measurement noise (one value per decade of family_ranges()), printed as
/// a table and drawn as SVG heat maps, one panel per method. A cell is
/// coloured by the ratio RMSE after / RMSE before: green where the
/// corrector reduces the error, red where it adds to it, white at no change.

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <apps/seed000_methods.hpp>
#include <apps/svg.hpp>
#include <posefuse/eval/metrics.hpp>

namespace posefuse::apps::seed000 {

/// One method's RMSE over the grid; NaN where the run failed.
struct SweepTable {
  std::string method;
  Family family = Family::kCv;
  std::vector<double> process, measurement;  ///< grid values
  std::vector<std::vector<double>> rmse;     ///< rmse[i][j]: process[i], measurement[j] (m)
  double default_process = 0, default_measurement = 0;
};

/// The decade grid of a range: lo, 10 lo, ..., up to hi.
[[nodiscard]] inline std::vector<double> decade_grid(NoiseRange r) {
  const auto n = static_cast<std::size_t>(std::lround(std::log10(r.hi / r.lo))) + 1;
  return log_spaced(r.lo, r.hi, std::max<std::size_t>(n, 2));
}

/// The sweep of every family in `families` on `in` against `truth_xy`
/// (the RMSE needs the ground truth; the filters never see it). A family
/// with a smoother (cv, ctrv) gives two tables (cv, cv+rts).
inline std::vector<SweepTable> sweep(const PlanarInput& in, const std::vector<Eigen::Vector2d>& truth_xy,
                                     const std::vector<std::pair<Family, std::pair<double, double>>>& families) {
  std::vector<SweepTable> out;
  for (const auto& [f, defaults] : families) {
    const FamilyRanges r = family_ranges(f);
    SweepTable t;
    t.method = family_name(f);
    t.family = f;
    t.process = decade_grid(r.process);
    t.measurement = decade_grid(r.measurement);
    t.default_process = defaults.first;
    t.default_measurement = defaults.second;
    t.rmse.assign(t.process.size(), std::vector<double>(t.measurement.size(), std::nan("")));
    SweepTable smooth = t;
    smooth.method = std::string(family_name(f)) + "+rts";
    const bool has_smoother = f == Family::kCv || f == Family::kCtrv;
    for (std::size_t i = 0; i < t.process.size(); ++i)
      for (std::size_t j = 0; j < t.measurement.size(); ++j) {
        try {
          std::optional<MethodRun> s;
          const MethodRun run =
              run_family(in, f, t.process[i], t.measurement[j], has_smoother ? &s : nullptr);
          const double e = rmse_2d(truth_xy, run.points);
          t.rmse[i][j] = std::isfinite(e) ? e : std::nan("");
          if (s) {
            const double es = rmse_2d(truth_xy, s->points);
            smooth.rmse[i][j] = std::isfinite(es) ? es : std::nan("");
          }
        } catch (const std::exception&) {
          // Left NaN: printed as "n/a", drawn grey.
        }
      }
    out.push_back(std::move(t));
    if (has_smoother) out.push_back(std::move(smooth));
  }
  return out;
}

/// "1e-03" style label of a grid value.
[[nodiscard]] inline std::string grid_label(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.0e", v);
  return b;
}

/// Prints each table: rows process, columns measurement, RMSE in m.
inline void print_sweep(const std::vector<SweepTable>& tables, const std::string& estimate,
                        double rmse_before) {
  std::printf("\nSensitivity of %s (planar RMSE [m] over process x measurement noise; %.3f m before "
              "correction)\n",
              estimate.c_str(), rmse_before);
  for (const SweepTable& t : tables) {
    const auto [pu, mu] = family_units(t.family);
    std::printf("\n%s: rows %s, columns %s\n%-14s", t.method.c_str(), pu, mu, "");
    for (double m : t.measurement) std::printf(" %8s", grid_label(m).c_str());
    std::printf("\n");
    for (std::size_t i = 0; i < t.process.size(); ++i) {
      std::printf("%-14s", grid_label(t.process[i]).c_str());
      for (double v : t.rmse[i]) {
        if (std::isfinite(v)) std::printf(" %8.3f", v);
        else std::printf(" %8s", "n/a");
      }
      std::printf("\n");
    }
  }
}

/// Fill colour of a cell: green for ratio < 1, red for > 1 (saturating at
/// a factor of 2 either way, on a log scale), white at 1, grey for NaN.
[[nodiscard]] inline std::string heat_colour(double ratio) {
  if (!std::isfinite(ratio) || !(ratio > 0)) return "#bbbbbb";
  const double s = std::clamp(std::log2(ratio), -1.0, 1.0);  // -1 green .. +1 red
  const auto mix = [](double a, double b, double w) {
    return static_cast<int>(std::lround(a + (b - a) * w));
  };
  int r = 255, g = 255, b = 255;
  if (s < 0) r = mix(255, 26, -s), g = mix(255, 152, -s), b = mix(255, 80, -s);
  else r = mix(255, 215, s), g = mix(255, 48, s), b = mix(255, 39, s);
  char buf[8];
  std::snprintf(buf, sizeof buf, "#%02x%02x%02x", r, g, b);
  return buf;
}

/// The heat maps, two panels per row; the cell of the default setting is
/// outlined in black, the RMSE is written in each cell.
[[nodiscard]] inline std::string sweep_svg(const std::vector<SweepTable>& tables,
                                           const std::string& estimate, double rmse_before) {
  const double cell = 46, left = 90, top = 60, gap = 70, right = 20;
  std::size_t cols = 0, rows = 0;
  for (const auto& t : tables) {
    cols = std::max(cols, t.measurement.size());
    rows = std::max(rows, t.process.size());
  }
  const double panel_w = left + cell * static_cast<double>(cols) + right;
  const double panel_h = top + cell * static_cast<double>(rows) + gap;
  const std::size_t per_row = tables.size() > 1 ? 2 : 1;
  const std::size_t panel_rows = (tables.size() + per_row - 1) / per_row;
  const double title_h = 50;
  svg::Document doc(panel_w * static_cast<double>(per_row),
                    title_h + panel_h * static_cast<double>(std::max<std::size_t>(panel_rows, 1)));
  char head[200];
  std::snprintf(head, sizeof head, "%s: planar RMSE [m] after correction (before: %.3f m)",
                estimate.c_str(), rmse_before);
  doc.text({10, 22}, head, 15);
  doc.text({10, 40}, "green: lower than before, red: higher (saturating at x0.5 / x2), grey: run failed; "
                     "outlined: the default setting",
           11);
  for (std::size_t k = 0; k < tables.size(); ++k) {
    const SweepTable& t = tables[k];
    const double ox = panel_w * static_cast<double>(k % per_row);
    const double oy = title_h + panel_h * static_cast<double>(k / per_row);
    const auto [pu, mu] = family_units(t.family);
    doc.text({ox + left, oy + 20}, t.method, 14);
    const double n_rows = static_cast<double>(t.process.size());
    for (std::size_t i = 0; i < t.process.size(); ++i) {
      // Largest process noise on top.
      const double y = oy + top + cell * (n_rows - 1 - static_cast<double>(i));
      doc.text({ox + left - 6, y + cell / 2 + 4}, grid_label(t.process[i]), 11, svg::Anchor::kEnd);
      for (std::size_t j = 0; j < t.measurement.size(); ++j) {
        const double x = ox + left + cell * static_cast<double>(j);
        const double v = t.rmse[i][j];
        doc.rect({x, y, cell, cell}, heat_colour(rmse_before > 0 ? v / rmse_before : std::nan("")),
                 {"#ffffff", 1.0, {}});
        char txt[32];
        if (std::isfinite(v)) std::snprintf(txt, sizeof txt, "%.2f", v);
        else std::snprintf(txt, sizeof txt, "n/a");
        doc.text({x + cell / 2, y + cell / 2 + 4}, txt, 10, svg::Anchor::kMiddle);
      }
    }
    // The default setting's cell: nearest grid values in log.
    const auto nearest = [](const std::vector<double>& g, double v) {
      std::size_t best = 0;
      for (std::size_t i = 1; i < g.size(); ++i)
        if (std::abs(std::log(g[i] / v)) < std::abs(std::log(g[best] / v))) best = i;
      return best;
    };
    if (t.default_process > 0 && t.default_measurement > 0) {
      const std::size_t i = nearest(t.process, t.default_process);
      const std::size_t j = nearest(t.measurement, t.default_measurement);
      doc.rect({ox + left + cell * static_cast<double>(j),
                oy + top + cell * (n_rows - 1 - static_cast<double>(i)), cell, cell},
               "none", {"#000000", 2.0, {}});
    }
    for (std::size_t j = 0; j < t.measurement.size(); ++j)
      doc.text({ox + left + cell * (static_cast<double>(j) + 0.5), oy + top + cell * n_rows + 14},
               grid_label(t.measurement[j]), 10, svg::Anchor::kMiddle);
    doc.text({ox + left + cell * static_cast<double>(t.measurement.size()) / 2, oy + top + cell * n_rows + 32},
             std::string("measurement noise ") + mu, 11, svg::Anchor::kMiddle);
    doc.text({ox + 14, oy + top + cell * n_rows / 2}, std::string("process noise ") + pu, 11,
             svg::Anchor::kMiddle, -90);
  }
  return doc.str();
}

}  // namespace posefuse::apps::seed000
