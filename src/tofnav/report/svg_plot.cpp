// SPDX-License-Identifier: BSD-3-Clause
// Inline SVG figures for the report: histograms, line plots, grouped bars and a colour bar.
#include "tofnav/report/svg_plot.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "tofnav/core/require.hpp"
#include "tofnav/report/mesh_render.hpp"

namespace tofnav {
namespace {

struct Range {
  double lo = 0.0;
  double hi = 1.0;
};

// The finite values' range, widened when empty or flat so the axes stay drawable.
Range FiniteRange(std::span<const double> values,
                  Range range = {std::numeric_limits<double>::max(),
                                 -std::numeric_limits<double>::max()}) {
  for (double v : values) {
    if (!std::isfinite(v)) continue;
    range.lo = std::min(range.lo, v);
    range.hi = std::max(range.hi, v);
  }
  if (range.lo > range.hi) return {};
  if (range.hi - range.lo < 1e-12) return {range.lo - 0.5, range.hi + 0.5};
  return range;
}

// Room above the data for the legend, so bars and lines never run under it.
Range WithHeadroom(Range range) {
  constexpr double kHeadroom = 0.15;  // fraction of the data's span
  return {range.lo, range.hi + kHeadroom * (range.hi - range.lo)};
}

// About `count` ticks at 1, 2 or 5 times a power of ten.
std::vector<double> NiceTicks(Range range, int count = 5) {
  const double raw = (range.hi - range.lo) / count;
  const double power = std::pow(10.0, std::floor(std::log10(raw)));
  const double step = raw / power < 1.5 ? power : raw / power < 3.5 ? 2 * power : 5 * power;
  std::vector<double> ticks;
  for (double t = std::ceil(range.lo / step) * step; t <= range.hi + 1e-9 * step; t += step) {
    ticks.push_back(std::abs(t) < 1e-12 * step ? 0.0 : t);
  }
  return ticks;
}

std::string Px(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f", value);
  return text;
}

// The plot area inside the figure and the data-to-pixel mapping.
struct Frame {
  const PlotOptions& options;
  Range x;
  Range y;
  double left = 62.0, right = 14.0, top = 30.0, bottom = 44.0;
  double X(double v) const {
    return left + (v - x.lo) / (x.hi - x.lo) * (options.width_px - left - right);
  }
  double Y(double v) const {
    return options.height_px - bottom -
           (v - y.lo) / (y.hi - y.lo) * (options.height_px - top - bottom);
  }
};

std::string Open(const PlotOptions& o) {
  return "<svg xmlns=\"http://www.w3.org/2000/svg\" class=\"plot\" width=\"" +
         std::to_string(o.width_px) + "\" height=\"" + std::to_string(o.height_px) +
         "\" viewBox=\"0 0 " + std::to_string(o.width_px) + " " + std::to_string(o.height_px) +
         "\" font-family=\"sans-serif\" font-size=\"11\"><title>" + EscapeXml(o.title) +
         "</title>\n";
}

std::string Text(double x, double y, std::string_view text, std::string_view anchor,
                 std::string_view extra = "") {
  return "<text x=\"" + Px(x) + "\" y=\"" + Px(y) + "\" text-anchor=\"" + std::string(anchor) +
         "\"" + std::string(extra) + ">" + EscapeXml(text) + "</text>\n";
}

// Frame, grid, ticks, axis labels and title; `x_ticks` false for category axes.
std::string Axes(const Frame& f, bool x_ticks) {
  const PlotOptions& o = f.options;
  const double bottom_px = o.height_px - f.bottom;
  std::string s = "<rect x=\"" + Px(f.left) + "\" y=\"" + Px(f.top) + "\" width=\"" +
                  Px(o.width_px - f.left - f.right) + "\" height=\"" + Px(bottom_px - f.top) +
                  "\" fill=\"none\" stroke=\"#444\"/>\n";
  for (double t : NiceTicks(f.y)) {
    s += "<line x1=\"" + Px(f.left) + "\" x2=\"" + Px(o.width_px - f.right) + "\" y1=\"" +
         Px(f.Y(t)) + "\" y2=\"" + Px(f.Y(t)) + "\" stroke=\"#ddd\"/>\n";
    s += Text(f.left - 4, f.Y(t) + 4, FormatNumber(t), "end");
  }
  if (x_ticks) {
    for (double t : NiceTicks(f.x)) s += Text(f.X(t), bottom_px + 14, FormatNumber(t), "middle");
  }
  s += Text(0.5 * (f.left + o.width_px - f.right), o.height_px - 6.0, o.x_label, "middle");
  s += Text(14, 0.5 * (f.top + bottom_px), o.y_label, "middle",
            " transform=\"rotate(-90 14 " + Px(0.5 * (f.top + bottom_px)) + ")\"");
  s += Text(0.5 * o.width_px, 18, o.title, "middle", " font-weight=\"bold\"");
  return s;
}

std::string Legend(std::span<const PlotSeries> series, const Frame& f) {
  std::string s;
  double y = f.top + 14.0;
  for (const PlotSeries& p : series) {
    const double x = f.options.width_px - f.right - 120.0;
    s += "<rect x=\"" + Px(x) + "\" y=\"" + Px(y - 9) + "\" width=\"10\" height=\"10\" fill=\"" +
         EscapeXml(p.colour) + "\"/>\n";
    s += Text(x + 14, y, p.name, "start");
    y += 15.0;
  }
  return s;
}

std::string Rect(double x0, double y0, double x1, double y1, std::string_view colour,
                 std::string_view extra) {
  return "<rect class=\"bar\" x=\"" + Px(std::min(x0, x1)) + "\" y=\"" + Px(std::min(y0, y1)) +
         "\" width=\"" + Px(std::abs(x1 - x0)) + "\" height=\"" + Px(std::abs(y1 - y0)) +
         "\" fill=\"" + EscapeXml(colour) + "\"" + std::string(extra) + "/>\n";
}

std::vector<double> AllY(std::span<const PlotSeries> series) {
  std::vector<double> all;
  for (const PlotSeries& p : series) all.insert(all.end(), p.y.begin(), p.y.end());
  return all;
}

}  // namespace

void PlotOptions::Check() const {
  Require(width_px >= 120 && height_px >= 80, "PlotOptions: the figure must be at least 120x80 px");
}

std::string SvgHistogram(std::span<const double> bin_edges, std::span<const PlotSeries> series,
                         const PlotOptions& options) {
  options.Check();
  Require(bin_edges.size() >= 2, "SvgHistogram: need at least two bin edges");
  for (const PlotSeries& p : series) {
    Require(p.y.size() + 1 == bin_edges.size(), "SvgHistogram: counts do not match the bins");
  }
  const std::vector<double> counts = AllY(series);
  const Frame f{options, FiniteRange(bin_edges), WithHeadroom(FiniteRange(counts, {0.0, 0.0}))};
  std::string s = Open(options) + Axes(f, true);
  for (const PlotSeries& p : series) {
    for (std::size_t i = 0; i + 1 < bin_edges.size(); ++i) {
      const double count = std::isfinite(p.y[i]) ? std::max(0.0, p.y[i]) : 0.0;
      s += Rect(f.X(bin_edges[i]), f.Y(0.0), f.X(bin_edges[i + 1]), f.Y(count), p.colour,
                " fill-opacity=\"0.55\"");
    }
  }
  return s + Legend(series, f) + "</svg>\n";
}

std::string SvgLinePlot(std::span<const PlotSeries> series, const PlotOptions& options) {
  options.Check();
  std::vector<double> xs;
  for (const PlotSeries& p : series) {
    Require(p.x.size() == p.y.size(), "SvgLinePlot: x and y differ in length");
    xs.insert(xs.end(), p.x.begin(), p.x.end());
  }
  const std::vector<double> ys = AllY(series);
  const Frame f{options, FiniteRange(xs), WithHeadroom(FiniteRange(ys, {0.0, 0.0}))};
  std::string s = Open(options) + Axes(f, true);
  for (const PlotSeries& p : series) {
    std::string points;
    const auto flush = [&] {
      if (!points.empty()) {
        s += "<polyline class=\"line\" fill=\"none\" stroke-width=\"1.5\" stroke=\"" +
             EscapeXml(p.colour) + "\" points=\"" + points + "\"/>\n";
      }
      points.clear();
    };
    for (std::size_t i = 0; i < p.x.size(); ++i) {
      if (!std::isfinite(p.x[i]) || !std::isfinite(p.y[i])) {
        flush();
        continue;
      }
      points += (points.empty() ? "" : " ") + Px(f.X(p.x[i])) + "," + Px(f.Y(p.y[i]));
    }
    flush();
  }
  return s + Legend(series, f) + "</svg>\n";
}

std::string SvgBarChart(std::span<const std::string> categories, std::span<const PlotSeries> series,
                        const PlotOptions& options) {
  options.Check();
  for (const PlotSeries& p : series) {
    Require(p.y.size() == categories.size(), "SvgBarChart: one value per category expected");
  }
  const std::vector<double> values = AllY(series);
  const Frame f{options,
                {0.0, static_cast<double>(std::max<std::size_t>(1, categories.size()))},
                WithHeadroom(FiniteRange(values, {0.0, 0.0}))};
  std::string s = Open(options) + Axes(f, false);
  const double group_px = f.X(1.0) - f.X(0.0);
  const double bar_px =
      0.8 * group_px / static_cast<double>(std::max<std::size_t>(1, series.size()));
  for (std::size_t c = 0; c < categories.size(); ++c) {
    const double x0 = f.X(static_cast<double>(c)) + 0.1 * group_px;
    for (std::size_t k = 0; k < series.size(); ++k) {
      const double value = std::isfinite(series[k].y[c]) ? series[k].y[c] : 0.0;
      const double left = x0 + static_cast<double>(k) * bar_px;
      s += Rect(left, f.Y(0.0), left + bar_px, f.Y(value), series[k].colour, "");
    }
    s += Text(f.X(static_cast<double>(c) + 0.5), options.height_px - f.bottom + 14, categories[c],
              "middle");
  }
  return s + Legend(series, f) + "</svg>\n";
}

std::string SvgColourBar(double min, double max, std::string_view label, int width_px) {
  Require(width_px >= 120, "SvgColourBar: at least 120 px wide");
  constexpr int kStops = 16;
  const std::string w = std::to_string(width_px);
  std::string s = "<svg xmlns=\"http://www.w3.org/2000/svg\" class=\"plot colour-bar\" width=\"" +
                  w + "\" height=\"52\" viewBox=\"0 0 " + w +
                  " 52\" font-family=\"sans-serif\" font-size=\"11\"><title>" + EscapeXml(label) +
                  "</title>\n<defs><linearGradient id=\"error-gradient\">\n";
  for (int i = 0; i <= kStops; ++i) {
    const double t = static_cast<double>(i) / kStops;
    const Rgb8 c = ErrorColour(t);
    s += "<stop offset=\"" + Px(100.0 * t) + "%\" stop-color=\"rgb(" + std::to_string(c[0]) + "," +
         std::to_string(c[1]) + "," + std::to_string(c[2]) + ")\"/>\n";
  }
  const double x0 = 10.0;
  const double x1 = width_px - 10.0;
  s += "</linearGradient></defs>\n<rect x=\"" + Px(x0) + "\" y=\"4\" width=\"" + Px(x1 - x0) +
       "\" height=\"14\" fill=\"url(#error-gradient)\" stroke=\"#444\"/>\n";
  const Range range = FiniteRange(std::vector<double>{min, max});
  for (double t : NiceTicks(range, 4)) {
    const double x = x0 + (t - range.lo) / (range.hi - range.lo) * (x1 - x0);
    s += "<line x1=\"" + Px(x) + "\" x2=\"" + Px(x) + "\" y1=\"18\" y2=\"22\" stroke=\"#444\"/>\n";
    s += Text(x, 33, FormatNumber(t), "middle");
  }
  return s + Text(0.5 * width_px, 48, label, "middle") + "</svg>\n";
}

std::string EscapeXml(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&#39;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

std::string FormatNumber(double value, int significant) {
  if (!std::isfinite(value)) return "\u2013";
  const int digits = std::clamp(significant, 1, 17);
  char text[64];
  if (std::abs(value) < 1e15 && value == std::round(value)) {
    std::snprintf(text, sizeof text, "%.0f", value);  // counts and frames stay whole
  } else if (std::abs(value) >= 1.0 && std::abs(value) < 1e15) {
    // Fixed notation with `digits` significant digits, never an exponent for large values.
    const int whole = static_cast<int>(std::floor(std::log10(std::abs(value)))) + 1;
    std::snprintf(text, sizeof text, "%.*f", std::max(0, digits - whole), value);
    std::string fixed = text;  // "7.90" reads "7.9", like %g
    if (fixed.find('.') != std::string::npos) {
      fixed.erase(fixed.find_last_not_of('0') + 1);
      if (fixed.back() == '.') fixed.pop_back();
    }
    return fixed;
  } else {
    std::snprintf(text, sizeof text, "%.*g", digits, value);
  }
  return text;
}

}  // namespace tofnav
