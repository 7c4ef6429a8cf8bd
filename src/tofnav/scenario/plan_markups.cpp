// SPDX-License-Identifier: BSD-3-Clause
// 3D Slicer markups JSON writer for planned trajectories.
#include "tofnav/scenario/plan_markups.hpp"

#include <nlohmann/json.hpp>

#include "tofnav/io/file.hpp"

namespace tofnav {
namespace {

using OrderedJson = nlohmann::ordered_json;

constexpr const char* kMarkupsSchema =
    "https://raw.githubusercontent.com/slicer/slicer/master/Modules/Loadable/Markups/Resources/"
    "Schema/markups-schema-v1.0.3.json#";

OrderedJson ControlPoint(int id, const char* label, const Eigen::Vector3d& position) {
  return OrderedJson{{"id", std::to_string(id)},
                     {"label", label},
                     {"position", {position.x(), position.y(), position.z()}},
                     {"positionStatus", "defined"}};
}

}  // namespace

std::string EncodeTrajectoryMarkups(const std::vector<sim::Trajectory>& plan) {
  OrderedJson markups = OrderedJson::array();
  for (const sim::Trajectory& t : plan) {
    markups.push_back(OrderedJson{{"type", "Line"},
                                  {"name", t.name},
                                  {"coordinateSystem", "LPS"},
                                  {"coordinateUnits", "mm"},
                                  {"locked", true},
                                  {"controlPoints",
                                   {ControlPoint(1, "entry", t.entry_in_image),
                                    ControlPoint(2, "target", t.target_in_image)}}});
  }
  return OrderedJson{{"@schema", kMarkupsSchema}, {"markups", markups}}.dump(2) + "\n";
}

std::string EncodeLandmarkMarkups(const std::vector<sim::PlannedLandmark>& landmarks) {
  OrderedJson points = OrderedJson::array();
  for (std::size_t i = 0; i < landmarks.size(); ++i) {
    points.push_back(
        ControlPoint(static_cast<int>(i + 1), landmarks[i].name.c_str(), landmarks[i].in_image));
  }
  const OrderedJson markup{
      {"type", "Fiducial"},      {"name", "landmarks"}, {"coordinateSystem", "LPS"},
      {"coordinateUnits", "mm"}, {"locked", true},      {"controlPoints", points}};
  return OrderedJson{{"@schema", kMarkupsSchema}, {"markups", {markup}}}.dump(2) + "\n";
}

void WriteLandmarkMarkups(const std::filesystem::path& path,
                          const std::vector<sim::PlannedLandmark>& landmarks) {
  WriteFileAtomically(path, EncodeLandmarkMarkups(landmarks));
}

void WriteTrajectoryMarkups(const std::filesystem::path& path,
                            const std::vector<sim::Trajectory>& plan) {
  WriteFileAtomically(path, EncodeTrajectoryMarkups(plan));
}

}  // namespace tofnav
