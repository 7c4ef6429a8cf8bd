// SPDX-License-Identifier: BSD-3-Clause
// Tool poses CSV (and the helpers shared with the JSON codec): docs/tracking.md section 3.
#include "tofnav/casefile/tool_poses_io.hpp"

#include <array>
#include <charconv>
#include <cmath>
#include <stdexcept>

#include "tofnav/casefile/tool_poses_internal.hpp"
#include "tofnav/io/file.hpp"
#include "tofnav/io/io_error.hpp"

namespace tofnav {
namespace {

constexpr ToolStatus kStatuses[] = {ToolStatus::kOk, ToolStatus::kPartiallyOccluded,
                                    ToolStatus::kAmbiguous, ToolStatus::kTooFewMarkers,
                                    ToolStatus::kOutOfView};
constexpr double kUnitQuaternionTolerance = 1e-6;  // written with round-trip precision
constexpr const char* kPoseColumns[] = {"qw", "qx", "qy", "qz", "x_mm", "y_mm", "z_mm"};
constexpr const char* kPosePrefixes[] = {"", "filtered_", "world_"};
constexpr std::size_t kScalarColumns = 9;
constexpr std::size_t kColumns = kScalarColumns + 3 * 7;

std::string Header() {
  std::string h = "frame,host_ticks,time_s,tool,status,markers_used,marker_count,fre_mm,gated";
  for (const char* prefix : kPosePrefixes) {
    for (const char* c : kPoseColumns) h += std::string(",") + prefix + c;
  }
  return h;
}

std::string Number(double x) {
  std::array<char, 32> buffer{};
  const auto r = std::to_chars(buffer.data(), buffer.data() + buffer.size(), x);
  return {buffer.data(), r.ptr};
}

void AppendPose(std::string& row, const std::optional<Rigid3d>& pose) {
  if (!pose) {
    row += ",,,,,,,";
    return;
  }
  const Eigen::Quaterniond& q = pose->rotation;
  for (const double v : {q.w(), q.x(), q.y(), q.z(), pose->translation.x(), pose->translation.y(),
                         pose->translation.z()}) {
    row += ',';  // not "," + Number(v): GCC 12 -O3 warns falsely on that insert (bug 105651)
    row += Number(v);
  }
}

}  // namespace

namespace internal {

std::optional<Rigid3d> PoseFromValues(const std::array<double, 7>& v,
                                      const std::filesystem::path& path,
                                      std::optional<std::uint64_t> offset) {
  for (const double x : v) {
    if (!std::isfinite(x)) throw IoError(path, offset, "pose values must be finite");
  }
  const Eigen::Quaterniond q(v[0], v[1], v[2], v[3]);
  if (std::abs(q.norm() - 1.0) > kUnitQuaternionTolerance) {
    throw IoError(path, offset, "pose quaternion (w, x, y, z) must have unit norm");
  }
  return Rigid3d(q, Eigen::Vector3d(v[4], v[5], v[6]));
}

ToolStatus StatusFromName(std::string_view name, const std::filesystem::path& path,
                          std::optional<std::uint64_t> offset) {
  const std::optional<ToolStatus> s = ParseToolStatus(name);
  if (!s) throw IoError(path, offset, "unknown status '" + std::string(name) + "'");
  return *s;
}

}  // namespace internal

namespace {

using internal::PoseFromValues;
using internal::StatusFromName;

template <typename T>
T ParseField(std::string_view field, const std::filesystem::path& path, std::uint64_t offset,
             const char* what) {
  T value{};
  const auto r = std::from_chars(field.data(), field.data() + field.size(), value);
  if (r.ec != std::errc() || r.ptr != field.data() + field.size()) {
    throw IoError(path, offset,
                  std::string("expected ") + what + ", got '" + std::string(field) + "'");
  }
  return value;
}

std::vector<ToolPoseRecord> DecodeCsv(std::string_view text, const std::filesystem::path& path) {
  std::vector<ToolPoseRecord> records;
  std::size_t line_start = 0;
  bool header = true;
  while (line_start < text.size()) {
    std::size_t line_end = text.find('\n', line_start);
    if (line_end == std::string_view::npos) line_end = text.size();
    std::string_view line = text.substr(line_start, line_end - line_start);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    const std::size_t offset = line_start;
    line_start = line_end + 1;
    if (line.empty()) continue;
    if (header) {
      if (line != Header()) throw IoError(path, offset, "expected the header line " + Header());
      header = false;
      continue;
    }
    std::array<std::string_view, kColumns> f;
    std::array<std::size_t, kColumns> at{};
    std::size_t n = 0, pos = 0;
    while (true) {
      const std::size_t comma = line.find(',', pos);
      if (n == kColumns) throw IoError(path, offset + pos, "too many columns");
      at[n] = offset + pos;
      f[n++] = line.substr(pos, comma == std::string_view::npos ? comma : comma - pos);
      if (comma == std::string_view::npos) break;
      pos = comma + 1;
    }
    if (n != kColumns) {
      throw IoError(path, offset,
                    "expected " + std::to_string(kColumns) + " columns, got " + std::to_string(n));
    }
    ToolPoseRecord r;
    r.frame = ParseField<std::int64_t>(f[0], path, at[0], "a frame index");
    r.host_ticks = ParseField<std::uint64_t>(f[1], path, at[1], "host ticks");
    r.time_s = ParseField<double>(f[2], path, at[2], "a time [s]");
    if (f[3].empty()) throw IoError(path, at[3], "expected a tool name");
    r.tool = std::string(f[3]);
    r.status = StatusFromName(f[4], path, at[4]);
    r.markers_used = ParseField<int>(f[5], path, at[5], "a marker count");
    r.marker_count = ParseField<int>(f[6], path, at[6], "a marker count");
    r.fre_mm = ParseField<double>(f[7], path, at[7], "an FRE [mm]");
    r.gated = ParseField<int>(f[8], path, at[8], "0 or 1") != 0;
    std::optional<Rigid3d>* poses[] = {&r.ahat_from_tool, &r.filtered_ahat_from_tool,
                                       &r.world_from_tool};
    for (std::size_t p = 0; p < 3; ++p) {
      const std::size_t first = kScalarColumns + 7 * p;
      bool any = false, all = true;
      for (std::size_t k = 0; k < 7; ++k) {
        any |= !f[first + k].empty();
        all &= !f[first + k].empty();
      }
      if (!any) continue;
      if (!all) throw IoError(path, at[first], "a pose needs all 7 values or none");
      std::array<double, 7> v{};
      for (std::size_t k = 0; k < 7; ++k) {
        v[k] = ParseField<double>(f[first + k], path, at[first + k], "a number");
      }
      *poses[p] = PoseFromValues(v, path, at[first]);
    }
    records.push_back(std::move(r));
  }
  if (header) throw IoError(path, 0, "expected the header line " + Header());
  return records;
}

}  // namespace

std::optional<ToolStatus> ParseToolStatus(std::string_view name) {
  for (const ToolStatus s : kStatuses) {
    if (name == ToString(s)) return s;
  }
  return std::nullopt;
}

std::string EncodeToolPosesCsv(std::span<const ToolPoseRecord> records) {
  std::string out = Header() + "\n";
  for (const ToolPoseRecord& r : records) {
    if (r.tool.empty() || r.tool.find_first_of(",\"\r\n") != std::string::npos) {
      throw std::invalid_argument("tool name '" + r.tool +
                                  "' cannot go into a CSV cell (empty, comma, quote or newline)");
    }
    std::string row = std::to_string(r.frame) + "," + std::to_string(r.host_ticks) + "," +
                      Number(r.time_s) + "," + r.tool + "," + ToString(r.status) + "," +
                      std::to_string(r.markers_used) + "," + std::to_string(r.marker_count) + "," +
                      Number(r.fre_mm) + "," + (r.gated ? "1" : "0");
    AppendPose(row, r.ahat_from_tool);
    AppendPose(row, r.filtered_ahat_from_tool);
    AppendPose(row, r.world_from_tool);
    out += row + "\n";
  }
  return out;
}

std::vector<ToolPoseRecord> DecodeToolPoses(std::string_view text,
                                            const std::filesystem::path& path) {
  const std::size_t first = text.find_first_not_of(" \t\r\n");
  if (first != std::string_view::npos && text[first] == '{')
    return internal::DecodeToolPosesJson(text, path);
  return DecodeCsv(text, path);
}

std::vector<ToolPoseRecord> ReadToolPoses(const std::filesystem::path& path) {
  const std::vector<std::uint8_t> bytes = ReadFileBytes(path);
  return DecodeToolPoses({reinterpret_cast<const char*>(bytes.data()), bytes.size()}, path);
}

void WriteToolPoses(const std::filesystem::path& path, std::span<const ToolPoseRecord> records) {
  WriteFileAtomically(path, path.extension() == ".json" ? EncodeToolPosesJson(records)
                                                        : EncodeToolPosesCsv(records));
}

}  // namespace tofnav
