// SPDX-License-Identifier: BSD-3-Clause
// The SVG figures: element counts, geometry of known bars, escaping and input checks.
#include "tofnav/report/svg_plot.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <regex>

#include "tofnav/core/require.hpp"
#include "tofnav/report/report_test_helpers.hpp"

namespace tofnav {
namespace {

using testing::Count;

TEST(SvgHistogram, DrawsOneBarPerBinAndSeries) {
  const std::vector<double> edges = {-2, -1, 0, 1, 2, 3};
  const PlotSeries series[] = {{.name = "before", .y = {1, 4, 9, 4, 1}},
                               {.name = "after", .y = {0, 2, 12, 2, 0}}};
  const std::string svg = SvgHistogram(edges, series, {.title = "t"});
  EXPECT_EQ(svg.rfind("<svg xmlns=\"http://www.w3.org/2000/svg\"", 0), 0u);
  EXPECT_EQ(Count(svg, "<rect class=\"bar\""), 10);
  EXPECT_EQ(Count(svg, "</svg>"), 1);
  EXPECT_NE(svg.find(">before</text>"), std::string::npos);  // legend
  EXPECT_NE(svg.find(">after</text>"), std::string::npos);
}

TEST(SvgHistogram, BarHeightsAreProportionalToCounts) {
  // Plot area: 300 - 30 (top) - 44 (bottom) = 226 px tall; the y axis runs from 0 to 11.5
  // (10 plus 15 % headroom for the legend).
  const std::vector<double> edges = {0, 1, 2};
  const PlotSeries series[] = {{.name = "n", .y = {10, 5}}};
  const std::string svg = SvgHistogram(edges, series, {.width_px = 400, .height_px = 300});
  const std::regex height("class=\"bar\"[^>]* height=\"([0-9.]+)\"");
  std::vector<double> heights;
  for (auto it = std::sregex_iterator(svg.begin(), svg.end(), height); it != std::sregex_iterator();
       ++it) {
    heights.push_back(std::stod((*it)[1]));
  }
  ASSERT_EQ(heights.size(), 2u);
  constexpr double kPxTol = 0.051;  // one decimal in the SVG
  EXPECT_NEAR(heights[0], 226.0 * 10.0 / 11.5, kPxTol);
  EXPECT_NEAR(heights[1], 226.0 * 5.0 / 11.5, kPxTol);
}

TEST(SvgHistogram, RejectsCountsThatDoNotMatchTheBins) {
  const std::vector<double> edges = {0, 1, 2};
  const PlotSeries series[] = {{.name = "n", .y = {1, 2, 3}}};
  EXPECT_THROW(SvgHistogram(edges, series), PreconditionError);
}

TEST(SvgLinePlot, BreaksTheLineAtMissingPoints) {
  const double nan = std::nan("");
  const PlotSeries series[] = {{.name = "a", .x = {0, 1, 2, 3, 4}, .y = {1, 2, nan, 3, 4}},
                               {.name = "b", .x = {0, 1}, .y = {0, 0}}};
  const std::string svg = SvgLinePlot(series);
  EXPECT_EQ(Count(svg, "<polyline class=\"line\""), 3);
}

TEST(SvgBarChart, DrawsOneBarPerCategoryAndSeriesWithLabels) {
  const std::vector<std::string> categories = {"left <EVD>", "right"};
  const PlotSeries series[] = {{.name = "ours", .y = {1.5, 2.0}},
                               {.name = "paper", .y = {2.5, 3.0}}};
  const std::string svg = SvgBarChart(categories, series);
  EXPECT_EQ(Count(svg, "<rect class=\"bar\""), 4);
  EXPECT_NE(svg.find(">left &lt;EVD&gt;</text>"), std::string::npos);
}

TEST(SvgColourBar, HasAGradientAndTicksOverTheRange) {
  const std::string svg = SvgColourBar(0.0, 4.0, "|error| [mm]");
  EXPECT_EQ(Count(svg, "<stop "), 17);
  EXPECT_NE(svg.find(">0</text>"), std::string::npos);
  EXPECT_NE(svg.find(">4</text>"), std::string::npos);
}

TEST(EscapeXml, EscapesMarkupCharacters) {
  EXPECT_EQ(EscapeXml("a<b>&\"c'"), "a&lt;b&gt;&amp;&quot;c&#39;");
}

TEST(FormatNumber, UsesSignificantDigitsWholeNumbersAndADashForNonFinite) {
  EXPECT_EQ(FormatNumber(3.14159), "3.14");
  EXPECT_EQ(FormatNumber(1234.5, 5), "1234.5");
  EXPECT_EQ(FormatNumber(1234.6), "1235");  // no exponent for large values
  EXPECT_EQ(FormatNumber(52000.0), "52000");
  EXPECT_EQ(FormatNumber(7.9), "7.9");  // no trailing zeros
  EXPECT_EQ(FormatNumber(0.00412), "0.00412");
  EXPECT_EQ(FormatNumber(-2.0), "-2");
  EXPECT_EQ(FormatNumber(std::nan("")), "\u2013");
}

}  // namespace
}  // namespace tofnav
