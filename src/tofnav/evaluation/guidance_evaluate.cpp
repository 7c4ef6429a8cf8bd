// SPDX-License-Identifier: BSD-3-Clause
// Placed plan against the simulation's truth chain, per frame and trajectory.
#include "tofnav/evaluation/guidance_evaluate.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <nlohmann/json.hpp>
#include <numbers>
#include <stdexcept>

#include "tofnav/evaluation/truth_hits.hpp"
#include "tofnav/io/file.hpp"

namespace tofnav {
namespace {

using Json = nlohmann::json;

// The truth of one frame: rig_from_image (what the display shows relative to the head, free of
// the headset's pose error) and world_from_rig as recorded.
struct TruthFrame {
  double timestamp_s = 0.0;
  Rigid3d world_from_rig_recorded;
  Rigid3d world_from_image_true;
  Rigid3d rig_from_image_true;
};

std::vector<TruthFrame> ReadTruthFrames(const std::filesystem::path& truth_path) {
  const std::vector<std::uint8_t> bytes = ReadFileBytes(truth_path);
  try {
    const Json truth = Json::parse(bytes.begin(), bytes.end());
    std::string tool;  // any tool rigid with the patient gives the same chain
    for (const auto& [name, t] : truth.at("tools").items()) {
      if (t.value("rigid_with_patient", false) && truth.contains(name + "_from_image")) {
        tool = name;
        break;
      }
    }
    if (tool.empty()) throw std::runtime_error("no tool rigid with the patient");
    const Rigid3d tool_from_image = TruthMatrix(truth.at(tool + "_from_image"));
    const double tick_s = 1e-7;
    std::vector<TruthFrame> frames;
    for (const Json& f : truth.at("frames")) {
      TruthFrame t;
      t.timestamp_s = f.at("timestamp").get<double>() * tick_s;
      t.world_from_rig_recorded = TruthMatrix(f.at("world_from_rig"));
      t.rig_from_image_true = TruthMatrix(f.at("rig_from_ahat")) *
                              TruthMatrix(f.at("ahat_from_" + tool)) * tool_from_image;
      t.world_from_image_true = TruthMatrix(f.at("world_from_rig_true")) * t.rig_from_image_true;
      frames.push_back(t);
    }
    return frames;
  } catch (const std::exception& e) {
    throw std::runtime_error(truth_path.string() +
                             ": not a simulation truth.json with a patient: " + e.what());
  }
}

double AngleDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b)) * 180.0 / std::numbers::pi;
}

}  // namespace

GuidanceEvaluation EvaluateGuidanceAgainstTruth(std::span<const PlacedFrame> placed,
                                                const std::filesystem::path& truth_json,
                                                const std::vector<Trajectory>& plan) {
  const std::vector<TruthFrame> truth = ReadTruthFrames(truth_json);
  constexpr double kSameFrameS = 1e-4;  // timestamps are 100 ns ticks
  std::vector<double> entry_display, entry_world, direction;
  std::map<std::string, std::vector<double>> entry_by_name, direction_by_name;
  GuidanceEvaluation result;
  for (const PlacedFrame& p : placed) {
    const auto it =
        std::lower_bound(truth.begin(), truth.end(), p.timestamp_s - kSameFrameS,
                         [](const TruthFrame& t, double s) { return t.timestamp_s < s; });
    if (it == truth.end() || std::abs(it->timestamp_s - p.timestamp_s) > kSameFrameS) {
      ++result.unmatched;
      continue;
    }
    ++result.frames;
    // Shown relative to the head: the recorded head pose cancels within a frame (Eq. 8).
    const Rigid3d rig_from_image = it->world_from_rig_recorded.Inverse() * p.world_from_image;
    for (const Trajectory& t : plan) {
      const double e =
          (rig_from_image * t.entry_lps_mm - it->rig_from_image_true * t.entry_lps_mm).norm();
      const double w =
          (p.world_from_image * t.entry_lps_mm - it->world_from_image_true * t.entry_lps_mm).norm();
      const Eigen::Vector3d axis = t.target_lps_mm - t.entry_lps_mm;
      const double d =
          AngleDeg(rig_from_image.rotation * axis, it->rig_from_image_true.rotation * axis);
      entry_display.push_back(e);
      entry_world.push_back(w);
      direction.push_back(d);
      entry_by_name[t.name].push_back(e);
      direction_by_name[t.name].push_back(d);
    }
  }
  if (entry_display.empty()) {
    throw std::runtime_error("no placed frame matches the timestamps of " + truth_json.string());
  }
  result.entry_mm = Summarise(entry_display);
  result.entry_world_mm = Summarise(entry_world);
  result.direction_deg = Summarise(direction);
  for (const Trajectory& t : plan) {
    result.trajectories.push_back(
        {t.name, Summarise(entry_by_name[t.name]), Summarise(direction_by_name[t.name])});
  }
  return result;
}

}  // namespace tofnav
