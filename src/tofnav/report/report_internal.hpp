// SPDX-License-Identifier: BSD-3-Clause
// Internal to report/: the HTML building blocks and one function per demo stage's section.
#pragma once

#include <exception>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "tofnav/core/image.hpp"
#include "tofnav/core/point_cloud.hpp"
#include "tofnav/report/report.hpp"

namespace tofnav::report_internal {

using Json = nlohmann::json;

/// What every section reads: the whole demo.json, its directory and the options.
struct Context {
  const Json& demo;
  const std::filesystem::path& dir;
  const ReportOptions& options;
  const Json& Stage(std::string_view name) const;  // null Json when absent
  const Json& Paper(std::string_view name) const;  // demo["paper"][name], or null
};

/// object[key], or null Json when absent or `object` is not an object.
const Json& Field(const Json& object, std::string_view key);
/// A number field, NaN when absent or not a number; a string field, "" when absent.
double Number(const Json& object, std::string_view key);
std::string Text(const Json& object, std::string_view key);
/// The element of object[array] whose "name" is `name`, or null Json.
const Json& Named(const Json& object, std::string_view array, std::string_view name);
/// The paper's entry for a named item (a depth object, a tool, a trajectory): the element of
/// paper[array] with that name, else paper[name] when it is an object, else `paper` itself when
/// `overall` (the paper's figure for the whole stage), else null Json.
const Json& PaperEntry(const Json& paper, std::string_view array, std::string_view name,
                       bool overall);
/// The numbers of object[key], empty when absent.
std::vector<double> Numbers(const Json& object, std::string_view key);

/// "" when the stage ran; else the reason to show ("stage absent from demo.json", its error).
std::string NotRunReason(const Json& stage);
/// `<p class="not-run">not run: reason</p>`.
std::string NotRun(std::string_view reason);
/// The page's start up to and including <body>: doctype, title and the report's inline style.
std::string PageHead(std::string_view title);
/// A table; cells are HTML already (escape text with EscapeXml).
std::string Table(const std::vector<std::string>& header,
                  const std::vector<std::vector<std::string>>& rows);
/// A row {label, ours[key], paper[key]} of an ours-beside-the-paper table.
std::vector<std::string> CompareRow(std::string label, const Json& ours, const Json& paper,
                                    std::string_view key);
/// `<figure id=id>body<figcaption>caption</figcaption></figure>`.
std::string Figure(std::string_view id, std::string_view caption, const std::string& body);
/// An <img> with the image as a base64 PNG data URI.
std::string PngImage(const Image<Rgb8>& image, std::string_view alt);
/// The i-th colour of the report's qualitative palette (tools, trajectories).
std::string SeriesColour(std::size_t i);
/// The colours of "before"/"ours" and "after"/"paper" series.
inline constexpr std::string_view kBeforeColour = "#d62728";
inline constexpr std::string_view kAfterColour = "#1f77b4";
/// A number cell (FormatNumber: "–" when NaN, e.g. a figure the paper does not give).
std::string Cell(double value, int significant = 3);
/// A path named by the stage's `key`, resolved against the demo directory; throws
/// std::runtime_error when the stage does not name one.
std::filesystem::path Artefact(const Context& context, const Json& stage, std::string_view key);
/// A CSV file with a header line, as text cells; IoError when it cannot be read.
struct Csv {
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> cells;
  /// One column as numbers (NaN where a cell is not one); throws when the column is missing.
  std::vector<double> Column(std::string_view name) const;
  std::vector<std::string> TextColumn(std::string_view name) const;
};
Csv ReadCsv(const std::filesystem::path& path);

/// The stage's acceptance checks ({figure, value, op, limit, met}) as a table, its "note", and
/// the paper's "note"/"where"; "" when there are none.
std::string StageNotes(const Json& stage, const Json& paper);
/// build(), or NotRun(reason) when it throws: an unreadable artefact loses only its figure.
template <typename Build>
std::string OrNotRun(Build&& build) {
  try {
    return build();
  } catch (const std::exception& e) {
    return NotRun(e.what());
  }
}

std::string MarkerErrorSection(const Context& context);
std::string DepthSection(const Context& context);
std::string ReconstructionSection(const Context& context);
std::string RegistrationSection(const Context& context);
std::string TrackingSection(const Context& context);
std::string GuidanceSection(const Context& context);

}  // namespace tofnav::report_internal
