// SPDX-License-Identifier: BSD-3-Clause
// The report from the hand-made fixture (tests/fixtures/report): contents, self-containment, and
// "not run" for failed stages and unreadable artefacts.
#include "tofnav/report/report.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "tofnav/core/require.hpp"
#include "tofnav/io/file.hpp"
#include "tofnav/io/io_error.hpp"
#include "tofnav/io/io_test_helpers.hpp"
#include "tofnav/report/report_test_helpers.hpp"

namespace tofnav {
namespace {

using testing::Count;

const std::filesystem::path kFixture = std::filesystem::path(TOFNAV_TESTS_DIR) / "fixtures/report";
const ReportOptions kSmall{.render_size_px = 96};  // small renderings keep the tests fast

bool Contains(const std::string& text, const std::string& needle) {
  return text.find(needle) != std::string::npos;
}

nlohmann::json FixtureJson() {
  std::ifstream in(kFixture / "demo.json");
  return nlohmann::json::parse(in);
}

void WriteJson(const std::filesystem::path& dir, const nlohmann::json& demo) {
  WriteFileAtomically(dir / "demo.json", demo.dump(1));
}

TEST(RenderHtmlReport, HasEveryTableAndFigureOfTheFixture) {
  const std::string html = RenderHtmlReport(kFixture, kSmall);
  for (const char* id :
       {"fig-marker-curve", "fig-depth-histogram", "fig-reconstruction-render", "fig-colour-bar",
        "fig-reconstruction-histogram", "fig-registration-overlay", "fig-tracking-position",
        "fig-tracking-rotation", "fig-guidance-entry", "fig-guidance-angle"}) {
    EXPECT_EQ(Count(html, std::string("<figure id=\"") + id + "\""), 1) << id;
  }
  EXPECT_EQ(Count(html, "src=\"data:image/png;base64,"), 5);  // 3 head views + 2 overlay views
  EXPECT_EQ(Count(html, "<svg "), 8);
  EXPECT_FALSE(Contains(html, "not run")) << "every fixture stage ran";
  // Bars: depth 8 bins x 2 series, reconstruction 6 bins, guidance 2 charts x 3 trajectories x
  // (ours, paper).
  EXPECT_EQ(Count(html, "<rect class=\"bar\""), 8 * 2 + 6 + 2 * 3 * 2);
  EXPECT_TRUE(Contains(html, "Head: <b>phantom</b>"));
  EXPECT_TRUE(Contains(html, "elapsed 12.5 s"));
  EXPECT_TRUE(Contains(html, "<td>Kocher left</td><td>2.3</td><td>1.6</td>"));
  EXPECT_TRUE(Contains(html, "<td>TRE, mean over targets [mm]</td><td>1.4</td><td>1.8</td>"));
  // The paper's figures: the target object falls back to the stage's overall figures, other
  // items match by name (a list entry, or an object named like the item).
  EXPECT_TRUE(Contains(html,
                       "<td>head *</td><td>52000</td><td>7.9</td><td>2.1</td><td>0.6</td>"
                       "<td>1.1</td><td>92.4</td><td>8</td><td>0.9</td><td>89</td>"));
  EXPECT_TRUE(Contains(html,
                       "<td>stage &lt;plate&gt;</td><td>8000</td><td>4</td><td>1.5</td>"
                       "<td>2.5</td><td>1.4</td><td>37.5</td><td>\u2013</td>"));
  EXPECT_TRUE(Contains(html,
                       "<td>photopolymer</td><td>5</td><td>1.1</td><td>0.7</td>"
                       "<td>0.56</td><td>0.61</td>"));
  EXPECT_TRUE(Contains(html, "<td>Keen</td><td>2</td><td>2.4</td><td>2.2</td><td>2</td>"));
  EXPECT_TRUE(Contains(html, "<td>Keen</td><td>2.1</td>"));  // registration target TRE
  // Acceptance checks and notes of the stages and the paper.
  EXPECT_TRUE(Contains(html,
                       "<td>tre_mm</td><td>1.4</td><td>&lt;=</td><td>1</td>"
                       "<td><span class=\"missed\">MISSED</span></td>"));
  EXPECT_TRUE(Contains(html, "<span class=\"ok\">met</span>"));
  EXPECT_TRUE(Contains(html, "Note: hand-made fixture, not a run"));
  EXPECT_TRUE(Contains(html, "Paper: Table I (fixture)"));
  EXPECT_TRUE(Contains(html, "Paper figures: fixture stand-in for the paper&#39;s figures"));
  // Per-tool tracking rows fall back to the paper's overall figures.
  EXPECT_TRUE(Contains(html,
                       "<td>stylet</td><td>6</td><td>83.3</td><td>0.62</td><td>0.35</td>"
                       "<td>0</td><td>0.6</td><td>0.4</td>"));
}

TEST(RenderHtmlReport, IsSelfContained) {
  const std::string html = RenderHtmlReport(kFixture, kSmall);
  EXPECT_FALSE(Contains(html, "<script"));
  EXPECT_FALSE(Contains(html, "<link"));
  EXPECT_FALSE(Contains(html, "src=\"http"));
  EXPECT_FALSE(Contains(html, "href=\"http"));
  EXPECT_FALSE(Contains(html, "url(http"));
  EXPECT_FALSE(Contains(html, "@import"));
}

TEST(RenderHtmlReport, ShowsWhyAStageDidNotRunAndKeepsTheOthers) {
  const testing::TempDir dir("report_not_run");
  nlohmann::json demo = FixtureJson();
  demo["stages"]["guidance"] = {{"ok", false}, {"error", "headframe <lost>"}};
  demo["stages"].erase("tracking");
  demo["stages"]["reconstruction"]["mesh_error_ply"] = "missing.ply";  // the others are absent too
  WriteJson(dir.path(), demo);
  const std::string html = RenderHtmlReport(dir.path(), kSmall);
  EXPECT_TRUE(Contains(html, "not run: headframe &lt;lost&gt;"));
  EXPECT_TRUE(Contains(html, "not run: stage absent from demo.json"));
  EXPECT_TRUE(Contains(html, "missing.ply"));
  EXPECT_TRUE(Contains(html, "<td>median error [mm]</td><td>0.9</td><td>1</td>"));  // table kept
  EXPECT_TRUE(Contains(html, "<figure id=\"fig-depth-histogram\""));
  EXPECT_FALSE(Contains(html, "<figure id=\"fig-guidance-entry\""));
  EXPECT_FALSE(Contains(html, "<figure id=\"fig-tracking-position\""));
}

TEST(RenderHtmlReport, SurvivesFieldsOfTheWrongType) {
  const testing::TempDir dir("report_types");
  nlohmann::json demo = FixtureJson();
  demo["head"] = 7;
  demo["paper"] = "none";
  demo["stages"]["depth"]["objects"] = 5;
  demo["stages"]["depth"]["histogram"] = {{"bin_edges_mm", {0, 1, 2}}, {"before", {1}}};
  demo["stages"]["reconstruction"]["mesh_error_ply"] = 3;
  demo["stages"]["tracking"]["tools"] = {{{"name", 1}}, "x"};
  demo["stages"]["tracking"]["error_csv"] = "demo.json";  // no such columns
  demo["stages"]["guidance"]["ok"] = "yes";
  demo["stages"]["registration"]["acceptance"] = {{{"met", "no"}}};
  WriteJson(dir.path(), demo);
  const std::string html = RenderHtmlReport(dir.path(), kSmall);
  EXPECT_TRUE(Contains(html, "SvgHistogram: counts do not match the bins"));
  EXPECT_TRUE(Contains(html, "demo.json names no mesh_error_ply"));
  EXPECT_TRUE(Contains(html, "CSV has no column"));
  EXPECT_TRUE(Contains(html, "not run: stage failed (no error given)"));  // guidance
  EXPECT_TRUE(Contains(html, "skin.ply"));  // the artefacts stay in the fixture: not found here
  EXPECT_EQ(Count(html, "</section>"), 6);
}

TEST(WriteHtmlReport, WritesThePage) {
  const testing::TempDir dir("report_write");
  WriteHtmlReport(kFixture, dir.path() / "report.html", kSmall);
  const std::vector<std::uint8_t> bytes = ReadFileBytes(dir.path() / "report.html");
  EXPECT_EQ(std::string(bytes.begin(), bytes.end()), RenderHtmlReport(kFixture, kSmall));
}

TEST(RenderHtmlReport, ThrowsIoErrorForAMissingOrForeignSummary) {
  const testing::TempDir dir("report_bad");
  EXPECT_THROW(RenderHtmlReport(dir.path()), IoError);
  WriteFileAtomically(dir.path() / "demo.json", std::string("{\"format\": "));
  EXPECT_THROW(RenderHtmlReport(dir.path()), IoError);
  WriteFileAtomically(dir.path() / "demo.json", std::string("{\"format\": \"other\"}"));
  EXPECT_THROW(RenderHtmlReport(dir.path()), IoError);
  WriteFileAtomically(dir.path() / "demo.json", std::string("[1, 2]"));
  EXPECT_THROW(RenderHtmlReport(dir.path()), IoError);
}

TEST(ReportOptions, RejectsBadValues) {
  EXPECT_THROW(ReportOptions{.render_size_px = 8}.Check(), PreconditionError);
  EXPECT_THROW(ReportOptions{.error_max_mm = -1.0}.Check(), PreconditionError);
}

}  // namespace
}  // namespace tofnav
