// SPDX-License-Identifier: BSD-3-Clause
// Tool JSON (read, write) and NDI .rom marker import.
#include "tofnav/casefile/tool_json.hpp"

#include <cctype>
#include <cmath>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "tofnav/casefile/json_number.hpp"
#include "tofnav/io/binary.hpp"
#include "tofnav/io/file.hpp"
#include "tofnav/io/io_error.hpp"

namespace tofnav {
namespace {

using OrderedJson = nlohmann::ordered_json;

constexpr std::size_t kRomCountOffset = 28;
constexpr std::size_t kRomMarkersOffset = 72;

Eigen::Vector3d Vector(const OrderedJson& value, const std::filesystem::path& path,
                       const std::string& what) {
  if (!value.is_array() || value.size() != 3) {
    throw IoError(path, std::nullopt, what + " must be an array of 3 numbers");
  }
  return {FiniteJsonNumber(value[0], path, what), FiniteJsonNumber(value[1], path, what),
          FiniteJsonNumber(value[2], path, what)};
}

// The first present key of `names`, or nullptr.
const OrderedJson* Find(const OrderedJson& object, std::initializer_list<const char*> names) {
  for (const char* name : names) {
    const auto it = object.find(name);
    if (it != object.end()) return &*it;
  }
  return nullptr;
}

ToolGeometry Checked(ToolGeometry tool, const std::filesystem::path& path) {
  try {
    tool.Check();
  } catch (const std::invalid_argument& e) {
    throw IoError(path, std::nullopt, std::string("invalid tool: ") + e.what());
  }
  return tool;
}

}  // namespace

ToolGeometry DecodeToolJson(std::string_view text, const std::filesystem::path& path) {
  OrderedJson json;
  try {
    json = OrderedJson::parse(text.begin(), text.end());
  } catch (const OrderedJson::parse_error& e) {
    throw IoError(path, e.byte > 0 ? e.byte - 1 : 0, std::string("malformed JSON: ") + e.what());
  } catch (const OrderedJson::exception& e) {  // e.g. a number that overflows a double
    throw IoError(path, std::nullopt, std::string("malformed JSON: ") + e.what());
  }
  if (!json.is_object()) throw IoError(path, std::nullopt, "expected a JSON object");
  ToolGeometry tool;
  const OrderedJson* name = Find(json, {"name"});
  if (name == nullptr || !name->is_string()) throw IoError(path, std::nullopt, "expected \"name\"");
  tool.name = name->get<std::string>();
  const OrderedJson* markers = Find(json, {"markers"});
  if (markers == nullptr || !markers->is_array()) {
    throw IoError(path, std::nullopt, "expected \"markers\": [[x, y, z], ...]");
  }
  for (std::size_t i = 0; i < markers->size(); ++i) {
    tool.markers_in_tool.push_back(
        Vector((*markers)[i], path, "markers[" + std::to_string(i) + "]"));
  }
  if (const OrderedJson* type = Find(json, {"marker_type"})) {
    const std::string t = type->is_string() ? type->get<std::string>() : "";
    if (t == "sphere") {
      tool.marker_type = MarkerType::kSphere;
    } else if (t == "flat" || t == "disc") {
      tool.marker_type = MarkerType::kDisc;
    } else {
      throw IoError(path, std::nullopt, "marker_type must be \"sphere\" or \"flat\"");
    }
  }
  if (const OrderedJson* d = Find(json, {"marker_diameter_mm", "marker_diameter"})) {
    tool.marker_diameter_mm = FiniteJsonNumber(*d, path, "marker_diameter_mm");
  }
  if (const OrderedJson* v = Find(json, {"min_visible"})) {
    if (!v->is_number_integer())
      throw IoError(path, std::nullopt, "min_visible must be an integer");
    tool.min_visible = v->get<int>();
  }
  if (const OrderedJson* f = Find(json, {"max_fre_mm"}))
    tool.max_fre_mm = FiniteJsonNumber(*f, path, "max_fre_mm");
  if (const OrderedJson* tip = Find(json, {"tip_mm", "tip"}); tip != nullptr && !tip->is_null()) {
    tool.tip_in_tool = Vector(*tip, path, "tip_mm");
  }
  return Checked(std::move(tool), path);
}

std::string EncodeToolJson(const ToolGeometry& tool) {
  OrderedJson json;
  json["name"] = tool.name;
  OrderedJson markers = OrderedJson::array();
  for (const Eigen::Vector3d& p : tool.markers_in_tool) markers.push_back({p.x(), p.y(), p.z()});
  json["markers"] = markers;
  json["marker_type"] = tool.marker_type == MarkerType::kSphere ? "sphere" : "flat";
  json["marker_diameter_mm"] = tool.marker_diameter_mm;
  json["min_visible"] = tool.min_visible;
  json["max_fre_mm"] = tool.max_fre_mm;
  if (tool.tip_in_tool) {
    json["tip_mm"] = {tool.tip_in_tool->x(), tool.tip_in_tool->y(), tool.tip_in_tool->z()};
  }
  return json.dump(2) + "\n";
}

ToolGeometry ReadToolJson(const std::filesystem::path& path) {
  const std::vector<std::uint8_t> bytes = ReadFileBytes(path);
  return DecodeToolJson(std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()),
                        path);
}

void WriteToolJson(const std::filesystem::path& path, const ToolGeometry& tool) {
  WriteFileAtomically(path, EncodeToolJson(tool));
}

ToolGeometry DecodeNdiRom(std::span<const std::uint8_t> bytes, const std::filesystem::path& path,
                          double diameter_mm) {
  ByteReader reader(bytes, path);
  reader.Skip(kRomCountOffset, "SROM header");
  const int count = reader.Le<std::uint8_t>("marker count");
  if (count < 3) {
    throw IoError(path, kRomCountOffset,
                  "expected at least 3 markers, found " + std::to_string(count));
  }
  reader.Skip(kRomMarkersOffset - kRomCountOffset - 1, "SROM header");
  ToolGeometry tool;
  tool.name = path.stem().string();
  tool.marker_diameter_mm = diameter_mm;
  for (int i = 0; i < count; ++i) {
    const std::uint64_t offset = reader.absolute_offset();
    const double x = reader.Le<float>("marker x"), y = reader.Le<float>("marker y"),
                 z = reader.Le<float>("marker z");
    if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z)) {
      throw IoError(path, offset, "non-finite marker position");
    }
    tool.markers_in_tool.emplace_back(x, y, z);
  }
  return Checked(std::move(tool), path);
}

ToolGeometry ReadNdiRom(const std::filesystem::path& path, double diameter_mm) {
  return DecodeNdiRom(ReadFileBytes(path), path, diameter_mm);
}

ToolGeometry ReadToolFile(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext == ".rom" ? ReadNdiRom(path) : ReadToolJson(path);
}

}  // namespace tofnav
