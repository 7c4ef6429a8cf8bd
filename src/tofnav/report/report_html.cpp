// SPDX-License-Identifier: BSD-3-Clause
// Internal to report/: the HTML building blocks shared by the stage sections.
#include <charconv>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "tofnav/io/file.hpp"
#include "tofnav/report/png.hpp"
#include "tofnav/report/report_internal.hpp"
#include "tofnav/report/svg_plot.hpp"

namespace tofnav::report_internal {
namespace {

const Json& NullJson() {
  static const Json kNull;
  return kNull;
}

std::size_t ColumnIndex(const std::vector<std::string>& header, std::string_view name) {
  for (std::size_t i = 0; i < header.size(); ++i) {
    if (header[i] == name) return i;
  }
  throw std::runtime_error("CSV has no column '" + std::string(name) + "'");
}

std::string Trimmed(std::string text) {
  while (!text.empty() && (text.back() == '\r' || text.back() == ' ')) text.pop_back();
  while (!text.empty() && text.front() == ' ') text.erase(text.begin());
  return text;
}

}  // namespace

const Json& Field(const Json& object, std::string_view key) {
  if (!object.is_object()) return NullJson();
  const auto it = object.find(key);
  return it == object.end() ? NullJson() : *it;
}

const Json& Context::Stage(std::string_view name) const {
  return Field(Field(demo, "stages"), name);
}

const Json& Context::Paper(std::string_view name) const {
  return Field(Field(demo, "paper"), name);
}

double Number(const Json& object, std::string_view key) {
  const Json& value = Field(object, key);
  return value.is_number() ? value.get<double>() : std::numeric_limits<double>::quiet_NaN();
}

std::string Text(const Json& object, std::string_view key) {
  const Json& value = Field(object, key);
  if (value.is_string()) return value.get<std::string>();
  return value.is_null() ? "" : value.dump();
}

const Json& Named(const Json& object, std::string_view array, std::string_view name) {
  const Json& items = Field(object, array);
  if (!items.is_array()) return NullJson();
  for (const Json& item : items) {
    if (Text(item, "name") == name) return item;
  }
  return NullJson();
}

const Json& PaperEntry(const Json& paper, std::string_view array, std::string_view name,
                       bool overall) {
  if (const Json& named = Named(paper, array, name); !named.is_null()) return named;
  if (const Json& own = Field(paper, name); own.is_object()) return own;
  return overall ? paper : NullJson();
}

std::string StageNotes(const Json& stage, const Json& paper) {
  std::string s;
  if (const Json& checks = Field(stage, "acceptance"); checks.is_array() && !checks.empty()) {
    std::vector<std::vector<std::string>> rows;
    for (const Json& check : checks) {
      const bool met = Field(check, "met") == true;
      rows.push_back(
          {EscapeXml(Text(check, "figure")), Cell(Number(check, "value"), 4),
           EscapeXml(Text(check, "op")), Cell(Number(check, "limit"), 4),
           met ? "<span class=\"ok\">met</span>" : "<span class=\"missed\">MISSED</span>"});
    }
    s += "<p>Acceptance:</p>\n" + Table({"figure", "value", "", "limit", ""}, rows);
  }
  for (const auto& [object, label] : {std::pair{&stage, "Note"}, std::pair{&paper, "Paper"}}) {
    for (const char* key : {"note", "where"}) {
      if (const std::string text = Text(*object, key); !text.empty()) {
        s += "<p class=\"meta\">" + std::string(label) + ": " + EscapeXml(text) + "</p>\n";
      }
    }
  }
  return s;
}

std::vector<double> Numbers(const Json& object, std::string_view key) {
  std::vector<double> out;
  const Json& values = Field(object, key);
  if (!values.is_array()) return out;
  for (const Json& v : values) {
    out.push_back(v.is_number() ? v.get<double>() : std::numeric_limits<double>::quiet_NaN());
  }
  return out;
}

std::string NotRunReason(const Json& stage) {
  if (!stage.is_object()) return "stage absent from demo.json";
  const Json& ok = Field(stage, "ok");
  if (ok.is_boolean() && ok.get<bool>()) return "";
  const std::string error = Text(stage, "error");
  return error.empty() ? "stage failed (no error given)" : error;
}

std::string NotRun(std::string_view reason) {
  return "<p class=\"not-run\">not run: " + EscapeXml(reason) + "</p>\n";
}

std::string Table(const std::vector<std::string>& header,
                  const std::vector<std::vector<std::string>>& rows) {
  std::string s = "<table>\n<tr>";
  for (const std::string& h : header) s += "<th>" + h + "</th>";
  s += "</tr>\n";
  for (const std::vector<std::string>& row : rows) {
    s += "<tr>";
    for (const std::string& cell : row) s += "<td>" + cell + "</td>";
    s += "</tr>\n";
  }
  return s + "</table>\n";
}

std::string Figure(std::string_view id, std::string_view caption, const std::string& body) {
  return "<figure id=\"" + EscapeXml(id) + "\">\n" + body + "<figcaption>" + EscapeXml(caption) +
         "</figcaption>\n</figure>\n";
}

std::string PngImage(const Image<Rgb8>& image, std::string_view alt) {
  return "<img class=\"render\" width=\"" + std::to_string(image.width()) + "\" height=\"" +
         std::to_string(image.height()) + "\" alt=\"" + EscapeXml(alt) +
         "\" src=\"data:image/png;base64," + Base64Encode(EncodePng(image)) + "\">\n";
}

std::vector<std::string> CompareRow(std::string label, const Json& ours, const Json& paper,
                                    std::string_view key) {
  return {std::move(label), Cell(Number(ours, key)), Cell(Number(paper, key))};
}

std::string SeriesColour(std::size_t i) {
  constexpr std::string_view kPalette[] = {"#1f77b4", "#ff7f0e", "#2ca02c", "#d62728",
                                           "#9467bd", "#8c564b", "#e377c2", "#17becf"};
  return std::string(kPalette[i % std::size(kPalette)]);
}

std::string Cell(double value, int significant) { return FormatNumber(value, significant); }

std::filesystem::path Artefact(const Context& context, const Json& stage, std::string_view key) {
  const Json& relative = Field(stage, key);
  if (!relative.is_string() || relative.get<std::string>().empty()) {
    throw std::runtime_error("demo.json names no " + std::string(key));
  }
  return context.dir / relative.get<std::string>();
}

Csv ReadCsv(const std::filesystem::path& path) {
  const std::vector<std::uint8_t> bytes = ReadFileBytes(path);
  std::istringstream in(std::string(bytes.begin(), bytes.end()));
  Csv csv;
  std::string line;
  for (bool first = true; std::getline(in, line); first = false) {
    std::vector<std::string> cells;
    std::istringstream cells_in(line);
    for (std::string cell; std::getline(cells_in, cell, ',');) cells.push_back(Trimmed(cell));
    if (first) {
      csv.header = std::move(cells);
    } else if (!cells.empty()) {
      csv.cells.push_back(std::move(cells));
    }
  }
  return csv;
}

std::vector<double> Csv::Column(std::string_view name) const {
  const std::size_t i = ColumnIndex(header, name);
  std::vector<double> out;
  out.reserve(cells.size());
  for (const std::vector<std::string>& row : cells) {
    double value = std::numeric_limits<double>::quiet_NaN();
    if (i < row.size()) {
      const char* begin = row[i].data();
      const char* end = begin + row[i].size();
      const auto [ptr, ec] = std::from_chars(begin, end, value);
      if (ec != std::errc() || ptr != end) value = std::numeric_limits<double>::quiet_NaN();
    }
    out.push_back(value);
  }
  return out;
}

std::vector<std::string> Csv::TextColumn(std::string_view name) const {
  const std::size_t i = ColumnIndex(header, name);
  std::vector<std::string> out;
  out.reserve(cells.size());
  for (const std::vector<std::string>& row : cells) out.push_back(i < row.size() ? row[i] : "");
  return out;
}

}  // namespace tofnav::report_internal
