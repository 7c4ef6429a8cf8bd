// SPDX-License-Identifier: BSD-3-Clause
// The evaluation report: one self-contained HTML page from a `tofnav demo` output directory.
#include "tofnav/report/report.hpp"

#include <algorithm>

#include "tofnav/core/require.hpp"
#include "tofnav/io/file.hpp"
#include "tofnav/io/io_error.hpp"
#include "tofnav/io/json_bytes.hpp"
#include "tofnav/report/report_internal.hpp"
#include "tofnav/report/svg_plot.hpp"

namespace tofnav {
namespace {

using report_internal::Context;
using report_internal::Json;

// No external fonts, images or scripts: the page must render the same offline.
constexpr std::string_view kStyle = R"(<style>
body { font-family: sans-serif; margin: 2em auto; max-width: 1100px; color: #222; }
h1 { margin-bottom: 0.2em; } h2 { border-bottom: 1px solid #ccc; padding-top: 0.6em; }
table { border-collapse: collapse; margin: 0.6em 0; font-size: 0.9em; }
th, td { border: 1px solid #ccc; padding: 3px 8px; text-align: right; }
th { background: #f2f2f2; } td:first-child, th:first-child { text-align: left; }
figure { display: inline-block; margin: 0.6em 1em 0.6em 0; vertical-align: top; }
figcaption { font-size: 0.85em; color: #555; max-width: 720px; }
.not-run, .missed { color: #a00; font-weight: bold; } .ok { color: #070; } .meta { color: #555; }
</style>
)";

Json ReadDemoJson(const std::filesystem::path& path) {
  Json demo = ParseJsonBytes<Json>(ReadFileBytes(path), path);
  const auto format = demo.is_object() ? demo.find("format") : demo.end();
  if (format == demo.end() || *format != "tofnav-demo") {
    throw IoError(path, 0, "not a tofnav demo summary (\"format\": \"tofnav-demo\" expected)");
  }
  return demo;
}

std::string Header(const Context& c) {
  using report_internal::Cell;
  using report_internal::Number;
  using report_internal::Text;
  std::string s = "<h1>tofnav evaluation report</h1>\n<p class=\"meta\">Head: <b>" +
                  EscapeXml(Text(c.demo, "head")) + "</b> &middot; tofnav " +
                  EscapeXml(Text(c.demo, "tofnav_version")) + " &middot; seed " +
                  EscapeXml(Text(c.demo, "seed")) + " &middot; elapsed " +
                  Cell(Number(c.demo, "elapsed_s")) + " s</p>\n";
  if (const std::string source = Text(report_internal::Field(c.demo, "paper"), "source");
      !source.empty()) {
    s += "<p class=\"meta\">Paper figures: " + EscapeXml(source) + "</p>\n";
  }
  s += "<p>The figures of Li et al. (EVD surgical guidance with AHAT time-of-flight tracking and "
       "reconstruction) beside this run's. Units: mm, degrees, seconds.</p>\n";
  // The pipeline's stages in order, then any other stage the demo wrote.
  std::vector<std::string> names = {"marker_error", "depth",    "reconstruction",
                                    "registration", "tracking", "guidance"};
  if (const Json& stages = report_internal::Field(c.demo, "stages"); stages.is_object()) {
    for (const auto& item : stages.items()) {
      if (std::find(names.begin(), names.end(), item.key()) == names.end()) {
        names.push_back(item.key());
      }
    }
  }
  std::vector<std::vector<std::string>> rows;
  for (const std::string& name : names) {
    const Json& stage = c.Stage(name);
    const std::string reason = report_internal::NotRunReason(stage);
    rows.push_back({EscapeXml(name),
                    reason.empty()
                        ? "<span class=\"ok\">ok</span>"
                        : "<span class=\"not-run\">not run: " + EscapeXml(reason) + "</span>",
                    Cell(Number(stage, "elapsed_s"))});
  }
  return s + report_internal::Table({"stage", "status", "elapsed [s]"}, rows);
}

// A section that failed to build (a malformed field) is replaced by its reason, so one bad
// entry never loses the rest of the report; the stage's checks and notes follow its figures.
std::string Guarded(std::string_view title, std::string_view stage,
                    std::string (*section)(const Context&), const Context& c) {
  const std::string notes = report_internal::OrNotRun([&] {
    return report_internal::NotRunReason(c.Stage(stage)).empty()
               ? report_internal::StageNotes(c.Stage(stage), c.Paper(stage))
               : std::string();
  });
  return "<section id=\"" + std::string(stage) + "\">\n<h2>" + EscapeXml(title) + "</h2>\n" +
         report_internal::OrNotRun([&] { return section(c); }) + notes + "</section>\n";
}

}  // namespace

void ReportOptions::Check() const {
  Require(render_size_px >= 64 && render_size_px <= 2048,
          "ReportOptions: render_size_px must be in [64, 2048]");
  Require(error_max_mm >= 0.0, "ReportOptions: error_max_mm must be >= 0 (0 = automatic)");
}

namespace report_internal {

std::string PageHead(std::string_view title) {
  return "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>" +
         EscapeXml(title) + "</title>\n" + std::string(kStyle) + "</head>\n<body>\n";
}

}  // namespace report_internal

std::string RenderHtmlReport(const std::filesystem::path& demo_dir, const ReportOptions& options) {
  options.Check();
  const Json demo = ReadDemoJson(demo_dir / "demo.json");
  const Context c{demo, demo_dir, options};
  std::string html = report_internal::PageHead("tofnav evaluation report") + Header(c);
  html += Guarded("Retro-reflective marker range error (f_rf)", "marker_error",
                  report_internal::MarkerErrorSection, c);
  html +=
      Guarded("Depth error before and after correction", "depth", report_internal::DepthSection, c);
  html += Guarded("Reconstruction", "reconstruction", report_internal::ReconstructionSection, c);
  html += Guarded("Registration", "registration", report_internal::RegistrationSection, c);
  html += Guarded("Tool tracking", "tracking", report_internal::TrackingSection, c);
  html += Guarded("Guidance", "guidance", report_internal::GuidanceSection, c);
  return html + "</body>\n</html>\n";
}

void WriteHtmlReport(const std::filesystem::path& demo_dir, const std::filesystem::path& out_html,
                     const ReportOptions& options) {
  WriteFileAtomically(out_html, RenderHtmlReport(demo_dir, options));
}

}  // namespace tofnav
