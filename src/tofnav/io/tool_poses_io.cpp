// SPDX-License-Identifier: BSD-3-Clause
// Tool poses CSV and JSON: one record per frame and tool (docs/tracking.md section 3).
#include "tofnav/io/tool_poses_io.hpp"

#include <array>
#include <charconv>
#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "tofnav/io/file.hpp"
#include "tofnav/io/io_error.hpp"

namespace tofnav {
namespace {

using Json = nlohmann::ordered_json;

constexpr ToolStatus kStatuses[] = {ToolStatus::kOk, ToolStatus::kPartiallyOccluded,
                                    ToolStatus::kAmbiguous, ToolStatus::kTooFewMarkers,
                                    ToolStatus::kOutOfView};
constexpr double kUnitQuaternionTolerance = 1e-6;  // written with round-trip precision
constexpr const char* kPoseColumns[] = {"qw", "qx", "qy", "qz", "x_mm", "y_mm", "z_mm"};
constexpr const char* kPosePrefixes[] = {"", "filtered_", "world_"};
constexpr std::size_t kScalarColumns = 9;
constexpr std::int64_t kMaxInt64 = std::numeric_limits<std::int64_t>::max();
constexpr std::int64_t kMaxMarkers = 1000;
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
    row += "," + Number(v);
  }
}

Json PoseJson(const std::optional<Rigid3d>& pose) {
  if (!pose) return nullptr;
  const Eigen::Quaterniond& q = pose->rotation;
  const Eigen::Vector3d& t = pose->translation;
  return Json{{"q_wxyz", {q.w(), q.x(), q.y(), q.z()}}, {"t_mm", {t.x(), t.y(), t.z()}}};
}

// A pose from 7 numbers (w, x, y, z, tx, ty, tz); the quaternion must be unit.
std::optional<Rigid3d> PoseFrom(const std::array<double, 7>& v, const std::filesystem::path& path,
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

ToolStatus StatusFrom(std::string_view name, const std::filesystem::path& path,
                      std::optional<std::uint64_t> offset) {
  const std::optional<ToolStatus> s = ParseToolStatus(name);
  if (!s) throw IoError(path, offset, "unknown status '" + std::string(name) + "'");
  return *s;
}

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
    r.status = StatusFrom(f[4], path, at[4]);
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
      *poses[p] = PoseFrom(v, path, at[first]);
    }
    records.push_back(std::move(r));
  }
  if (header) throw IoError(path, 0, "expected the header line " + Header());
  return records;
}

const Json& Field(const Json& object, const char* key, const std::filesystem::path& path) {
  const auto it = object.find(key);
  if (it == object.end()) throw IoError(path, std::nullopt, std::string("missing \"") + key + "\"");
  return *it;
}

// Integers are range-checked here: nlohmann converts out-of-range numbers without a check.
std::int64_t GetInt(const Json& object, const char* key, std::int64_t min, std::int64_t max,
                    const std::filesystem::path& path) {
  const Json& v = Field(object, key, path);
  if (!v.is_number_integer() ||
      (v.is_number_unsigned() && v.get<std::uint64_t>() > static_cast<std::uint64_t>(kMaxInt64)) ||
      v.get<std::int64_t>() < min || v.get<std::int64_t>() > max) {
    throw IoError(path, std::nullopt,
                  std::string("\"") + key + "\" must be an integer in [" + std::to_string(min) +
                      ", " + std::to_string(max) + "]");
  }
  return v.get<std::int64_t>();
}

double GetDouble(const Json& object, const char* key, const std::filesystem::path& path) {
  const Json& v = Field(object, key, path);
  if (!v.is_number())
    throw IoError(path, std::nullopt, std::string("\"") + key + "\" must be a number");
  return v.get<double>();
}

std::string GetString(const Json& object, const char* key, const std::filesystem::path& path) {
  const Json& v = Field(object, key, path);
  if (!v.is_string())
    throw IoError(path, std::nullopt, std::string("\"") + key + "\" must be a string");
  return v.get<std::string>();
}

std::vector<double> GetNumbers(const Json& object, const char* key, std::size_t count,
                               const std::filesystem::path& path) {
  const Json& v = Field(object, key, path);
  std::vector<double> out;
  if (v.is_array() && v.size() == count) {
    for (const Json& x : v) {
      if (!x.is_number()) break;
      out.push_back(x.get<double>());
    }
  }
  if (out.size() != count) {
    throw IoError(path, std::nullopt,
                  std::string("\"") + key + "\" must be " + std::to_string(count) + " numbers");
  }
  return out;
}

std::optional<Rigid3d> PoseFromJson(const Json& record, const char* key,
                                    const std::filesystem::path& path) {
  const auto it = record.find(key);
  if (it == record.end() || it->is_null()) return std::nullopt;
  if (!it->is_object()) throw IoError(path, std::nullopt, std::string(key) + " must be an object");
  const std::vector<double> q = GetNumbers(*it, "q_wxyz", 4, path);
  const std::vector<double> t = GetNumbers(*it, "t_mm", 3, path);
  return PoseFrom({q[0], q[1], q[2], q[3], t[0], t[1], t[2]}, path, std::nullopt);
}

std::vector<ToolPoseRecord> DecodeJson(std::string_view text, const std::filesystem::path& path) {
  Json json;
  try {
    json = Json::parse(text.begin(), text.end());
  } catch (const Json::parse_error& e) {
    throw IoError(path, e.byte > 0 ? e.byte - 1 : 0, std::string("malformed JSON: ") + e.what());
  } catch (const Json::exception& e) {
    throw IoError(path, std::nullopt, std::string("malformed JSON: ") + e.what());
  }
  if (!json.is_object() || json.value("format", Json()) != "tofnav-tool-poses") {
    throw IoError(path, std::nullopt, "expected {\"format\": \"tofnav-tool-poses\", ...}");
  }
  const auto records_it = json.find("records");
  if (records_it == json.end() || !records_it->is_array()) {
    throw IoError(path, std::nullopt, "expected \"records\": [...]");
  }
  std::vector<ToolPoseRecord> records;
  for (const Json& j : *records_it) {
    if (!j.is_object()) throw IoError(path, std::nullopt, "records must be objects");
    ToolPoseRecord r;
    r.frame = GetInt(j, "frame", 0, kMaxInt64, path);
    r.host_ticks = static_cast<std::uint64_t>(GetInt(j, "host_ticks", 0, kMaxInt64, path));
    r.time_s = GetDouble(j, "time_s", path);
    r.tool = GetString(j, "tool", path);
    r.status = StatusFrom(GetString(j, "status", path), path, std::nullopt);
    r.markers_used = static_cast<int>(GetInt(j, "markers_used", 0, kMaxMarkers, path));
    r.marker_count = static_cast<int>(GetInt(j, "marker_count", 0, kMaxMarkers, path));
    r.fre_mm = GetDouble(j, "fre_mm", path);
    const Json& gated = Field(j, "gated", path);
    if (!gated.is_boolean()) throw IoError(path, std::nullopt, "\"gated\" must be true or false");
    r.gated = gated.get<bool>();
    r.ahat_from_tool = PoseFromJson(j, "ahat_from_tool", path);
    r.filtered_ahat_from_tool = PoseFromJson(j, "filtered_ahat_from_tool", path);
    r.world_from_tool = PoseFromJson(j, "world_from_tool", path);
    records.push_back(std::move(r));
  }
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

std::string EncodeToolPosesJson(std::span<const ToolPoseRecord> records) {
  Json json{{"format", "tofnav-tool-poses"}, {"version", 1}, {"records", Json::array()}};
  for (const ToolPoseRecord& r : records) {
    json["records"].push_back(Json{{"frame", r.frame},
                                   {"host_ticks", r.host_ticks},
                                   {"time_s", r.time_s},
                                   {"tool", r.tool},
                                   {"status", ToString(r.status)},
                                   {"markers_used", r.markers_used},
                                   {"marker_count", r.marker_count},
                                   {"fre_mm", r.fre_mm},
                                   {"gated", r.gated},
                                   {"ahat_from_tool", PoseJson(r.ahat_from_tool)},
                                   {"filtered_ahat_from_tool", PoseJson(r.filtered_ahat_from_tool)},
                                   {"world_from_tool", PoseJson(r.world_from_tool)}});
  }
  return json.dump(1) + "\n";
}

std::vector<ToolPoseRecord> DecodeToolPoses(std::string_view text,
                                            const std::filesystem::path& path) {
  const std::size_t first = text.find_first_not_of(" \t\r\n");
  if (first != std::string_view::npos && text[first] == '{') return DecodeJson(text, path);
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
