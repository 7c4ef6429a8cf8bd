// SPDX-License-Identifier: BSD-3-Clause
// 3D Slicer markups JSON reader for planned trajectories (Line, or Entry/Target fiducials).
#include "tofnav/casefile/markups_read.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <utility>

#include "tofnav/io/file.hpp"
#include "tofnav/io/io_error.hpp"
#include "tofnav/io/json_bytes.hpp"

namespace tofnav {
namespace {

using Json = nlohmann::json;

std::string Lower(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return text;
}

/// Reads one markup; the JSON path in every message says where a fault is.
class MarkupReader {
 public:
  MarkupReader(const Json& markup, std::string where, const std::filesystem::path& source)
      : markup_(markup), where_(std::move(where)), source_(source) {}

  [[noreturn]] void Fail(const std::string& message) const {
    throw IoError(source_, std::nullopt, where_ + ": " + message);
  }

  std::string String(const char* key, const std::string& fallback) const {
    const auto it = markup_.find(key);
    if (it == markup_.end()) return fallback;
    if (!it->is_string()) Fail(std::string("\"") + key + "\": expected a string");
    return it->get<std::string>();
  }

  /// +1 or -1 for x and y: RAS positions are negated into LPS.
  double LpsSign() const {
    const std::string system = String("coordinateSystem", "LPS");
    if (system == "LPS") return 1.0;
    if (system == "RAS") return -1.0;
    Fail("\"coordinateSystem\": expected \"LPS\" or \"RAS\", found \"" + system + "\"");
  }

  double MmPerUnit() const {
    const auto it = markup_.find("coordinateUnits");
    if (it == markup_.end()) return 1.0;
    if (*it == "mm") return 1.0;
    if (*it == "um") return 1e-3;
    Fail("\"coordinateUnits\": expected \"mm\" or \"um\"");
  }

  /// The defined control points as (label, position in LPS mm), in file order.
  std::vector<std::pair<std::string, Eigen::Vector3d>> DefinedPoints() const {
    const double sign = LpsSign();
    const double scale = MmPerUnit();
    std::vector<std::pair<std::string, Eigen::Vector3d>> points;
    const auto it = markup_.find("controlPoints");
    if (it == markup_.end()) return points;
    if (!it->is_array()) Fail("\"controlPoints\": expected an array");
    for (std::size_t i = 0; i < it->size(); ++i) {
      const Json& point = (*it)[i];
      const std::string at = "controlPoints[" + std::to_string(i) + "]";
      if (!point.is_object()) Fail(at + ": expected an object");
      const auto status = point.find("positionStatus");
      if (status != point.end() && *status != "defined") continue;  // preview or undefined
      const auto position = point.find("position");
      if (position == point.end() || !position->is_array() || position->size() != 3) {
        Fail(at + ".position: expected 3 numbers");
      }
      Eigen::Vector3d p;
      for (int a = 0; a < 3; ++a) {
        const Json& value = (*position)[static_cast<std::size_t>(a)];
        if (!value.is_number() || !std::isfinite(value.get<double>())) {
          Fail(at + ".position: expected 3 finite numbers");
        }
        p[a] = value.get<double>() * scale;
      }
      p.x() *= sign;
      p.y() *= sign;
      const auto label = point.find("label");
      points.emplace_back(
          label != point.end() && label->is_string() ? label->get<std::string>() : std::string(),
          p);
    }
    return points;
  }

  /// The trajectory of a Line or of an Entry/Target fiducial list; nullopt for other markups.
  std::optional<Trajectory> Read(std::size_t ordinal) const {
    const std::string type = String("type", "");
    Trajectory trajectory;
    trajectory.name = String("name", "trajectory " + std::to_string(ordinal));
    if (type == "Line") {
      const auto points = DefinedPoints();
      if (points.size() != 2) {
        Fail("a Line needs exactly 2 defined control points (entry, target), found " +
             std::to_string(points.size()));
      }
      trajectory.entry_lps_mm = points[0].second;
      trajectory.target_lps_mm = points[1].second;
      return trajectory;
    }
    if (type != "Fiducial") return std::nullopt;
    const auto points = DefinedPoints();
    std::optional<Eigen::Vector3d> entry, target;
    for (const auto& [label, position] : points) {
      const std::string lower = Lower(label);
      if (lower == "entry") {
        if (entry) Fail("more than one point labelled Entry");
        entry = position;
      } else if (lower == "target") {
        if (target) Fail("more than one point labelled Target");
        target = position;
      }
    }
    if (!entry && !target) return std::nullopt;  // an ordinary fiducial list
    if (!entry || !target) Fail("a Fiducial trajectory needs both an Entry and a Target point");
    trajectory.entry_lps_mm = *entry;
    trajectory.target_lps_mm = *target;
    return trajectory;
  }

 private:
  const Json& markup_;
  std::string where_;
  const std::filesystem::path& source_;
};

/// Parses the document and calls `visit` with a reader for each markup of "markups".
template <typename Visit>
void ForEachMarkup(std::span<const std::uint8_t> bytes, const std::filesystem::path& source,
                   Visit&& visit) {
  const Json doc = ParseJsonBytes<Json>(bytes, source);
  if (!doc.is_object()) throw IoError(source, 0, "expected a JSON object with \"markups\"");
  const auto markups = doc.find("markups");
  if (markups == doc.end() || !markups->is_array()) {
    throw IoError(source, std::nullopt, "expected a \"markups\" array");
  }
  for (std::size_t i = 0; i < markups->size(); ++i) {
    const Json& markup = (*markups)[i];
    const std::string where = "markups[" + std::to_string(i) + "]";
    if (!markup.is_object()) throw IoError(source, std::nullopt, where + ": expected an object");
    visit(MarkupReader(markup, where, source));
  }
}

}  // namespace

std::vector<Trajectory> DecodeTrajectoryMarkups(std::span<const std::uint8_t> bytes,
                                                const std::filesystem::path& source) {
  std::vector<Trajectory> plan;
  ForEachMarkup(bytes, source, [&](const MarkupReader& markup) {
    if (auto trajectory = markup.Read(plan.size() + 1)) plan.push_back(std::move(*trajectory));
  });
  if (plan.empty()) {
    throw IoError(source, std::nullopt,
                  "no trajectory (expected a Line markup or Entry/Target fiducials)");
  }
  return plan;
}

std::vector<MarkupPoint> DecodeLabelledMarkupPointsJson(std::span<const std::uint8_t> bytes,
                                                        const std::filesystem::path& source) {
  std::vector<MarkupPoint> points;
  ForEachMarkup(bytes, source, [&](const MarkupReader& markup) {
    for (const auto& [label, position] : markup.DefinedPoints())
      points.push_back({label, position});
  });
  if (points.empty()) throw IoError(source, std::nullopt, "no defined control point");
  return points;
}

std::vector<Eigen::Vector3d> DecodeMarkupPointsJson(std::span<const std::uint8_t> bytes,
                                                    const std::filesystem::path& source) {
  std::vector<Eigen::Vector3d> points;
  for (const MarkupPoint& p : DecodeLabelledMarkupPointsJson(bytes, source)) {
    points.push_back(p.lps_mm);
  }
  return points;
}

namespace {

/// The bytes of a markups file and whether it is JSON (else .fcsv); IoError for other extensions.
std::pair<std::vector<std::uint8_t>, bool> ReadMarkupsFile(const std::filesystem::path& path) {
  const std::string extension = Lower(path.extension().string());
  if (extension != ".json" && extension != ".fcsv") {
    throw IoError(path, std::nullopt, "unknown markups extension (expected .mrk.json or .fcsv)");
  }
  return {ReadFileBytes(path), extension == ".json"};
}

}  // namespace

std::vector<Trajectory> ReadTrajectories(const std::filesystem::path& path) {
  const auto [bytes, json] = ReadMarkupsFile(path);
  return json ? DecodeTrajectoryMarkups(bytes, path) : DecodeTrajectoryFcsv(bytes, path);
}

std::vector<Eigen::Vector3d> ReadMarkupPoints(const std::filesystem::path& path) {
  const auto [bytes, json] = ReadMarkupsFile(path);
  return json ? DecodeMarkupPointsJson(bytes, path) : DecodeMarkupPointsFcsv(bytes, path);
}

std::vector<MarkupPoint> ReadLabelledMarkupPoints(const std::filesystem::path& path) {
  const auto [bytes, json] = ReadMarkupsFile(path);
  return json ? DecodeLabelledMarkupPointsJson(bytes, path)
              : DecodeLabelledMarkupPointsFcsv(bytes, path);
}

}  // namespace tofnav
