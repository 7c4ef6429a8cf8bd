// SPDX-License-Identifier: BSD-3-Clause
// `tofnav info` for truth.json (docs/simulator.md) and 3D Slicer markups (.mrk.json).
#include "tofnav/describe/describe_json.hpp"

#include <string>
#include <vector>

#include "tofnav/io/file.hpp"
#include "tofnav/io/io_error.hpp"

namespace tofnav::internal {
namespace {

using Json = nlohmann::json;
using OrderedJson = nlohmann::ordered_json;

OrderedJson TruthSummary(const Json& truth) {
  OrderedJson out{{"kind", "simulation truth"},
                  {"scenario", truth.value("scenario", "")},
                  {"seed", truth.value("seed", 0)},
                  {"profile", truth.value("profile", "")},
                  {"frames", truth.value("frame_count", 0)},
                  {"dropped_slots", truth.value("dropped_slots", 0)}};
  OrderedJson tools = OrderedJson::object();
  if (truth.contains("tools") && truth["tools"].is_object()) {
    for (const auto& [name, tool] : truth["tools"].items()) {
      tools[name] = {{"markers", tool.contains("markers") ? tool["markers"].size() : 0},
                     {"rigid_with_patient", tool.value("rigid_with_patient", false)}};
    }
  }
  out["tools"] = tools;
  out["materials"] = truth.contains("materials") ? truth["materials"].size() : 0;
  if (truth.contains("patient") && truth["patient"].is_object()) {
    const Json& patient = truth["patient"];
    out["patient"] = {
        {"head", patient.value("head", "")},
        {"trajectories", patient.contains("trajectories") ? patient["trajectories"].size() : 0}};
  }
  if (truth.contains("files")) out["files"] = truth["files"];
  return out;
}

OrderedJson MarkupsSummary(const Json& document) {
  OrderedJson out{{"kind", "markups"}, {"markups", document["markups"].size()}};
  std::vector<std::string> names;
  OrderedJson types = OrderedJson::object();
  for (const Json& markup : document["markups"]) {
    if (!markup.is_object()) continue;
    const std::string type = markup.value("type", "?");
    types[type] = types.value(type, 0) + 1;
    names.push_back(markup.value("name", ""));
  }
  out["types"] = types;
  out["names"] = names;
  return out;
}

}  // namespace

nlohmann::ordered_json DescribeJsonDocument(const std::filesystem::path& path) {
  const std::vector<std::uint8_t> bytes = ReadFileBytes(path);
  Json document;
  try {
    document = Json::parse(bytes.begin(), bytes.end());
  } catch (const Json::exception& e) {
    throw IoError(path, std::nullopt, std::string("invalid JSON: ") + e.what());
  }
  try {
    if (document.is_object() && document.value("format", "") == "tofnav-simulation-truth") {
      return TruthSummary(document);
    }
    if (document.is_object() && document.contains("markups") && document["markups"].is_array()) {
      return MarkupsSummary(document);
    }
  } catch (const Json::exception& e) {
    throw IoError(path, std::nullopt, std::string("unexpected JSON content: ") + e.what());
  }
  throw IoError(path, std::nullopt,
                "expected a simulation truth.json or a 3D Slicer markups (.mrk.json) file");
}

}  // namespace tofnav::internal
