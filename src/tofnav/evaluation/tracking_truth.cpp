// SPDX-License-Identifier: BSD-3-Clause
// Tool poses against a simulation's truth.json: frame matching and full visibility.
#include "tofnav/evaluation/tracking_truth.hpp"

#include <map>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "tofnav/core/units.hpp"
#include "tofnav/evaluation/truth_hits.hpp"
#include "tofnav/io/file.hpp"

namespace tofnav {
namespace {

using Json = nlohmann::json;

constexpr double kFocalPx = 254.0;  // centre focal length of the simulated AHAT, for blob sizes

struct TruthTool {
  std::vector<Eigen::Vector3d> markers_in_tool;
  std::vector<double> diameters_mm;
  std::vector<double> cutoffs_rad;  // retro-reflection entrance cut-off of each marker's material
};

Eigen::Vector3d Vector3(const Json& j) {
  return {j.at(0).get<double>(), j.at(1).get<double>(), j.at(2).get<double>()};
}

// Every marker of `tool` seen by >= min_pixels pixels, within its material's retro-reflection
// cut-off (a disc seen more obliquely reflects nothing), its blob (diameter f D / range) at
// least 2 px apart from every other marker's: the frames in which the whole tool can be seen.
bool FullyVisible(const Json& visible, const std::string& tool, const TruthTool& geometry,
                  const std::map<std::string, TruthTool>& tools, int min_pixels) {
  const Json& mine = visible.at(tool);
  if (mine.size() != geometry.markers_in_tool.size()) return false;
  const auto blob = [&](const std::string& name, const Json& m) {
    const double diameter_mm = tools.at(name).diameters_mm.at(m.at("marker").get<std::size_t>());
    return kFocalPx * diameter_mm / Vector3(m.at("centre_in_ahat")).norm();
  };
  for (const Json& m : mine) {
    const double diameter_px = blob(tool, m);
    const auto marker = m.at("marker").get<std::size_t>();
    if (m.at("pixel_count").get<int>() < min_pixels || !m.contains("pixel_uv") ||
        m.at("entrance_angle_rad").get<double>() >= geometry.cutoffs_rad.at(marker)) {
      return false;
    }
    const Eigen::Vector2d uv(m["pixel_uv"][0].get<double>(), m["pixel_uv"][1].get<double>());
    for (const auto& [other_name, others] : visible.items()) {
      for (const Json& o : others) {
        if ((other_name == tool && o.at("marker") == m.at("marker")) || !o.contains("pixel_uv")) {
          continue;
        }
        const Eigen::Vector2d ouv(o["pixel_uv"][0].get<double>(), o["pixel_uv"][1].get<double>());
        if ((uv - ouv).norm() < 0.5 * (diameter_px + blob(other_name, o)) + 2.0) return false;
      }
    }
  }
  return true;
}

}  // namespace

std::vector<ToolTruthEvaluation> EvaluateTrackingAgainstTruth(
    std::span<const ToolPoseRecord> records, const std::filesystem::path& truth_path,
    const TrackingEvaluationOptions& options, int min_marker_pixels) {
  Json truth;
  std::map<std::string, TruthTool> tools;
  std::map<std::int64_t, std::size_t> frame_at;  // frame index -> position in truth frames
  try {
    const std::vector<std::uint8_t> bytes = ReadFileBytes(truth_path);
    truth = Json::parse(bytes.begin(), bytes.end());
    std::map<std::string, double> cutoff_rad;
    for (const Json& m : truth.at("materials")) {
      cutoff_rad[m.at("name").get<std::string>()] = m.at("retro_entrance_cutoff_rad").get<double>();
    }
    for (const auto& [name, tool] : truth.at("tools").items()) {
      for (const Json& m : tool.at("markers")) {
        tools[name].markers_in_tool.push_back(Vector3(m.at("centre_in_tool")));
        tools[name].diameters_mm.push_back(m.at("diameter_mm").get<double>());
        tools[name].cutoffs_rad.push_back(cutoff_rad.at(m.at("material").get<std::string>()));
      }
    }
    const Json& frames = truth.at("frames");
    for (std::size_t i = 0; i < frames.size(); ++i)
      frame_at[frames[i].at("index").get<std::int64_t>()] = i;
  } catch (const Json::exception& e) {
    throw std::runtime_error(truth_path.string() + ": not a simulation truth.json: " + e.what());
  }

  std::vector<ToolTruthEvaluation> result;
  std::map<std::string, std::size_t> slot;
  for (const ToolPoseRecord& r : records) {
    if (!tools.contains(r.tool)) {
      throw std::runtime_error("tool '" + r.tool + "' of the poses is not in " +
                               truth_path.string());
    }
    const auto at = frame_at.find(r.frame);
    if (at == frame_at.end()) {
      throw std::runtime_error("frame " + std::to_string(r.frame) + " is not in the truth");
    }
    const Json& f = truth["frames"][at->second];
    if (f.at("timestamp").get<std::uint64_t>() != r.host_ticks) {
      throw std::runtime_error("frame " + std::to_string(r.frame) +
                               ": timestamps of poses and truth differ (another recording?)");
    }
    if (!slot.contains(r.tool)) {
      slot[r.tool] = result.size();
      result.push_back({r.tool, {}, {}, {}});
    }
    ToolEvaluationFrame e;
    e.true_ahat_from_tool = TruthMatrix(f.at("ahat_from_" + r.tool));
    e.fully_visible =
        FullyVisible(f.at("visible_markers"), r.tool, tools[r.tool], tools, min_marker_pixels);
    e.raw = r.ahat_from_tool;
    e.filtered = r.filtered_ahat_from_tool;
    if (r.filtered_ahat_from_tool && r.filtered_rotation_sd_deg > 0.0) {
      e.filtered_rotation_sd_rad = r.filtered_rotation_sd_deg * kDegToRad;
    }
    ToolTruthEvaluation& t = result[slot[r.tool]];
    t.frames.push_back(e);
    t.times_s.push_back(r.time_s);
  }
  for (ToolTruthEvaluation& t : result) {
    t.evaluation = EvaluateToolTracking(t.frames, tools[t.name].markers_in_tool, options);
  }
  return result;
}

}  // namespace tofnav
