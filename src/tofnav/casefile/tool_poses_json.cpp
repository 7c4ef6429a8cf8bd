// SPDX-License-Identifier: BSD-3-Clause
// Tool poses JSON: {"format": "tofnav-tool-poses", "records": [...]} (docs/tracking.md section 3).
#include <limits>
#include <nlohmann/json.hpp>

#include "tofnav/casefile/tool_poses_internal.hpp"
#include "tofnav/casefile/tool_poses_io.hpp"
#include "tofnav/io/io_error.hpp"
#include "tofnav/io/json_bytes.hpp"

namespace tofnav {
namespace {

using OrderedJson = nlohmann::ordered_json;
using internal::PoseFromValues;
using internal::StatusFromName;

constexpr std::int64_t kMaxInt64 = std::numeric_limits<std::int64_t>::max();
constexpr std::int64_t kMaxMarkers = 1000;

OrderedJson PoseJson(const std::optional<Rigid3d>& pose) {
  if (!pose) return nullptr;
  const Eigen::Quaterniond& q = pose->rotation;
  const Eigen::Vector3d& t = pose->translation;
  return OrderedJson{{"q_wxyz", {q.w(), q.x(), q.y(), q.z()}}, {"t_mm", {t.x(), t.y(), t.z()}}};
}

const OrderedJson& Field(const OrderedJson& object, const char* key,
                         const std::filesystem::path& path) {
  const auto it = object.find(key);
  if (it == object.end()) throw IoError(path, std::nullopt, std::string("missing \"") + key + "\"");
  return *it;
}

// Integers are range-checked here: nlohmann converts out-of-range numbers without a check.
std::int64_t GetInt(const OrderedJson& object, const char* key, std::int64_t min, std::int64_t max,
                    const std::filesystem::path& path) {
  const OrderedJson& v = Field(object, key, path);
  if (!v.is_number_integer() ||
      (v.is_number_unsigned() && v.get<std::uint64_t>() > static_cast<std::uint64_t>(kMaxInt64)) ||
      v.get<std::int64_t>() < min || v.get<std::int64_t>() > max) {
    throw IoError(path, std::nullopt,
                  std::string("\"") + key + "\" must be an integer in [" + std::to_string(min) +
                      ", " + std::to_string(max) + "]");
  }
  return v.get<std::int64_t>();
}

double GetDouble(const OrderedJson& object, const char* key, const std::filesystem::path& path) {
  const OrderedJson& v = Field(object, key, path);
  if (!v.is_number())
    throw IoError(path, std::nullopt, std::string("\"") + key + "\" must be a number");
  return v.get<double>();
}

std::string GetString(const OrderedJson& object, const char* key,
                      const std::filesystem::path& path) {
  const OrderedJson& v = Field(object, key, path);
  if (!v.is_string())
    throw IoError(path, std::nullopt, std::string("\"") + key + "\" must be a string");
  return v.get<std::string>();
}

std::vector<double> GetNumbers(const OrderedJson& object, const char* key, std::size_t count,
                               const std::filesystem::path& path) {
  const OrderedJson& v = Field(object, key, path);
  std::vector<double> out;
  if (v.is_array() && v.size() == count) {
    for (const OrderedJson& x : v) {
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

std::optional<Rigid3d> PoseFromJson(const OrderedJson& record, const char* key,
                                    const std::filesystem::path& path) {
  const auto it = record.find(key);
  if (it == record.end() || it->is_null()) return std::nullopt;
  if (!it->is_object()) throw IoError(path, std::nullopt, std::string(key) + " must be an object");
  const std::vector<double> q = GetNumbers(*it, "q_wxyz", 4, path);
  const std::vector<double> t = GetNumbers(*it, "t_mm", 3, path);
  return PoseFromValues({q[0], q[1], q[2], q[3], t[0], t[1], t[2]}, path, std::nullopt);
}

}  // namespace

namespace internal {

std::vector<ToolPoseRecord> DecodeToolPosesJson(std::string_view text,
                                                const std::filesystem::path& path) {
  const OrderedJson json = ParseJsonText<OrderedJson>(text, path);
  if (!json.is_object() || json.value("format", OrderedJson()) != "tofnav-tool-poses") {
    throw IoError(path, std::nullopt, "expected {\"format\": \"tofnav-tool-poses\", ...}");
  }
  const auto records_it = json.find("records");
  if (records_it == json.end() || !records_it->is_array()) {
    throw IoError(path, std::nullopt, "expected \"records\": [...]");
  }
  std::vector<ToolPoseRecord> records;
  for (const OrderedJson& j : *records_it) {
    if (!j.is_object()) throw IoError(path, std::nullopt, "records must be objects");
    ToolPoseRecord r;
    r.frame = GetInt(j, "frame", 0, kMaxInt64, path);
    r.host_ticks = static_cast<std::uint64_t>(GetInt(j, "host_ticks", 0, kMaxInt64, path));
    r.time_s = GetDouble(j, "time_s", path);
    r.tool = GetString(j, "tool", path);
    r.status = StatusFromName(GetString(j, "status", path), path, std::nullopt);
    r.markers_used = static_cast<int>(GetInt(j, "markers_used", 0, kMaxMarkers, path));
    r.marker_count = static_cast<int>(GetInt(j, "marker_count", 0, kMaxMarkers, path));
    r.fre_mm = GetDouble(j, "fre_mm", path);
    if (j.contains("rotation_sd_deg")) r.rotation_sd_deg = GetDouble(j, "rotation_sd_deg", path);
    if (j.contains("position_sd_mm")) r.position_sd_mm = GetDouble(j, "position_sd_mm", path);
    if (j.contains("filtered_rotation_sd_deg")) {
      r.filtered_rotation_sd_deg = GetDouble(j, "filtered_rotation_sd_deg", path);
    }
    const OrderedJson& gated = Field(j, "gated", path);
    if (!gated.is_boolean()) throw IoError(path, std::nullopt, "\"gated\" must be true or false");
    r.gated = gated.get<bool>();
    r.ahat_from_tool = PoseFromJson(j, "ahat_from_tool", path);
    r.filtered_ahat_from_tool = PoseFromJson(j, "filtered_ahat_from_tool", path);
    r.world_from_tool = PoseFromJson(j, "world_from_tool", path);
    records.push_back(std::move(r));
  }
  return records;
}

}  // namespace internal

std::string EncodeToolPosesJson(std::span<const ToolPoseRecord> records) {
  OrderedJson json{
      {"format", "tofnav-tool-poses"}, {"version", 1}, {"records", OrderedJson::array()}};
  for (const ToolPoseRecord& r : records) {
    json["records"].push_back(
        OrderedJson{{"frame", r.frame},
                    {"host_ticks", r.host_ticks},
                    {"time_s", r.time_s},
                    {"tool", r.tool},
                    {"status", ToString(r.status)},
                    {"markers_used", r.markers_used},
                    {"marker_count", r.marker_count},
                    {"fre_mm", r.fre_mm},
                    {"rotation_sd_deg", r.rotation_sd_deg},
                    {"position_sd_mm", r.position_sd_mm},
                    {"filtered_rotation_sd_deg", r.filtered_rotation_sd_deg},
                    {"gated", r.gated},
                    {"ahat_from_tool", PoseJson(r.ahat_from_tool)},
                    {"filtered_ahat_from_tool", PoseJson(r.filtered_ahat_from_tool)},
                    {"world_from_tool", PoseJson(r.world_from_tool)}});
  }
  return json.dump(1) + "\n";
}

}  // namespace tofnav
