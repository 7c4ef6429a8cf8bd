// SPDX-License-Identifier: BSD-3-Clause
// Inline SVG figures for the report: histograms, line plots, grouped bars and a colour bar.
#pragma once

#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace tofnav {

/// One named data series. Histograms and bar charts read only `y` (counts, or one value per
/// category); line plots read both.
struct PlotSeries {
  std::string name;
  std::vector<double> x;
  std::vector<double> y;
  std::string colour = "#1f77b4";  // any SVG colour
};

struct PlotOptions {
  int width_px = 560;
  int height_px = 300;
  std::string title;
  std::string x_label;
  std::string y_label;
  void Check() const;  // throws PreconditionError
};

/// Bars (class "bar") for every bin of every series, overlaid and translucent, plus a legend.
/// Throws PreconditionError unless every series has bin_edges.size() - 1 counts.
std::string SvgHistogram(std::span<const double> bin_edges, std::span<const PlotSeries> series,
                         const PlotOptions& options = {});

/// One polyline (class "line") per series over shared axes; non-finite points break the line.
std::string SvgLinePlot(std::span<const PlotSeries> series, const PlotOptions& options = {});

/// Grouped bars (class "bar"), one group per category, one bar per series in each group.
std::string SvgBarChart(std::span<const std::string> categories, std::span<const PlotSeries> series,
                        const PlotOptions& options = {});

/// A horizontal colour bar of ErrorColour from `min` to `max` with ticks and a label.
std::string SvgColourBar(double min, double max, std::string_view label, int width_px = 360);

/// Text safe inside XML/HTML elements and attribute values.
std::string EscapeXml(std::string_view text);

/// A number for a table or axis: whole numbers as they are, others with `significant`
/// significant digits (fixed notation from 1 up), "–" when not finite.
std::string FormatNumber(double value, int significant = 3);

}  // namespace tofnav
