// SPDX-License-Identifier: BSD-3-Clause
// Legacy 3D Slicer fiducial CSV (.fcsv) reader: consecutive points pair up as trajectories.
#include <charconv>
#include <cmath>
#include <optional>
#include <string>
#include <string_view>

#include "tofnav/casefile/markups_read.hpp"
#include "tofnav/io/io_error.hpp"

namespace tofnav {
namespace {

std::string_view Trim(std::string_view text) {
  while (!text.empty() && (text.front() == ' ' || text.front() == '\t')) text.remove_prefix(1);
  while (!text.empty() && (text.back() == ' ' || text.back() == '\t' || text.back() == '\r')) {
    text.remove_suffix(1);
  }
  return text;
}

/// Comma-separated fields; a field in double quotes may hold commas and "" for a quote.
std::vector<std::string> SplitCsv(std::string_view line) {
  std::vector<std::string> fields(1);
  bool quoted = false;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quoted) {
      if (c == '"' && i + 1 < line.size() && line[i + 1] == '"') {
        fields.back() += '"';
        ++i;
      } else if (c == '"') {
        quoted = false;
      } else {
        fields.back() += c;
      }
    } else if (c == '"') {
      quoted = true;
    } else if (c == ',') {
      fields.emplace_back();
    } else {
      fields.back() += c;
    }
  }
  for (std::string& field : fields) field = std::string(Trim(field));
  return fields;
}

/// The value after "<key> =" of a "# key = value" header line, if the line is that key's.
std::optional<std::string_view> HeaderValue(std::string_view line, std::string_view key) {
  line = Trim(line.substr(1));
  if (!line.starts_with(key)) return std::nullopt;
  line = Trim(line.substr(key.size()));
  if (!line.starts_with('=')) return std::nullopt;
  return Trim(line.substr(1));
}

struct Columns {
  std::size_t x = 1, y = 2, z = 3, label = 11;
};

struct Row {
  std::string label;
  Eigen::Vector3d position;
};

/// Every point row, in LPS; IoError when there is none.
std::vector<Row> DecodeRows(std::span<const std::uint8_t> bytes,
                            const std::filesystem::path& source) {
  const std::string_view text(reinterpret_cast<const char*>(bytes.data()), bytes.size());
  double sign = -1.0;  // legacy files without a CoordinateSystem line are RAS
  Columns columns;
  std::vector<Row> rows;
  std::size_t line_start = 0;
  while (line_start < text.size()) {
    std::size_t line_end = text.find('\n', line_start);
    if (line_end == std::string_view::npos) line_end = text.size();
    const std::string_view line = Trim(text.substr(line_start, line_end - line_start));
    const std::uint64_t offset = line_start;
    line_start = line_end + 1;
    if (line.empty()) continue;
    if (line.front() == '#') {
      if (const auto system = HeaderValue(line, "CoordinateSystem")) {
        if (*system == "LPS" || *system == "1") {
          sign = 1.0;
        } else if (*system == "RAS" || *system == "0") {
          sign = -1.0;
        } else {
          throw IoError(source, offset,
                        "expected CoordinateSystem LPS, RAS, 1 or 0 (IJK unsupported)");
        }
      } else if (const auto names = HeaderValue(line, "columns")) {
        const std::vector<std::string> fields = SplitCsv(*names);
        std::optional<std::size_t> x, y, z, label;
        for (std::size_t i = 0; i < fields.size(); ++i) {
          if (fields[i] == "x") x = i;
          if (fields[i] == "y") y = i;
          if (fields[i] == "z") z = i;
          if (fields[i] == "label") label = i;
        }
        if (!x || !y || !z) throw IoError(source, offset, "expected columns x, y and z");
        columns = {*x, *y, *z, label.value_or(fields.size())};
      }
      continue;
    }
    const std::vector<std::string> fields = SplitCsv(line);
    Row row;
    for (int a = 0; a < 3; ++a) {
      const std::size_t column = a == 0 ? columns.x : a == 1 ? columns.y : columns.z;
      if (column >= fields.size()) throw IoError(source, offset, "expected x, y and z columns");
      const std::string& field = fields[column];
      double value = 0.0;
      const auto [end, error] = std::from_chars(field.data(), field.data() + field.size(), value);
      if (error != std::errc() || end != field.data() + field.size() || !std::isfinite(value)) {
        throw IoError(source, offset, "expected a finite coordinate, found '" + field + "'");
      }
      row.position[a] = value;
    }
    row.position.x() *= sign;
    row.position.y() *= sign;
    if (columns.label < fields.size()) row.label = fields[columns.label];
    rows.push_back(std::move(row));
  }
  if (rows.empty()) throw IoError(source, bytes.size(), "no points");
  return rows;
}

}  // namespace

std::vector<Trajectory> DecodeTrajectoryFcsv(std::span<const std::uint8_t> bytes,
                                             const std::filesystem::path& source) {
  const std::vector<Row> rows = DecodeRows(bytes, source);
  if (rows.size() % 2 != 0) {
    throw IoError(
        source, bytes.size(),
        "odd number of points (" + std::to_string(rows.size()) + "): expected entry, target pairs");
  }
  std::vector<Trajectory> plan;
  for (std::size_t i = 0; i < rows.size(); i += 2) {
    Trajectory t;
    t.name = rows[i].label.empty() ? "trajectory " + std::to_string(i / 2 + 1) : rows[i].label;
    t.entry_lps_mm = rows[i].position;
    t.target_lps_mm = rows[i + 1].position;
    plan.push_back(std::move(t));
  }
  return plan;
}

std::vector<MarkupPoint> DecodeLabelledMarkupPointsFcsv(std::span<const std::uint8_t> bytes,
                                                        const std::filesystem::path& source) {
  std::vector<MarkupPoint> points;
  for (const Row& row : DecodeRows(bytes, source)) points.push_back({row.label, row.position});
  return points;
}

std::vector<Eigen::Vector3d> DecodeMarkupPointsFcsv(std::span<const std::uint8_t> bytes,
                                                    const std::filesystem::path& source) {
  std::vector<Eigen::Vector3d> points;
  for (const MarkupPoint& p : DecodeLabelledMarkupPointsFcsv(bytes, source)) {
    points.push_back(p.lps_mm);
  }
  return points;
}

}  // namespace tofnav
