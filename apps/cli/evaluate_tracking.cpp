// SPDX-License-Identifier: BSD-3-Clause
// tofnav evaluate tracking: a poses file against the simulator's truth.json.
#include <CLI/CLI.hpp>
#include <cstdlib>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <numbers>
#include <stdexcept>

#include "evaluate.hpp"
#include "tofnav/io/file.hpp"
#include "tofnav/io/tool_poses_io.hpp"
#include "tofnav/tracking/tracking_evaluation.hpp"

namespace tofnav {
namespace {

using Json = nlohmann::json;
using OrderedJson = nlohmann::ordered_json;

constexpr double kDegToRad = std::numbers::pi / 180.0;
constexpr double kFocalPx = 254.0;  // centre focal length of the simulated AHAT, for blob sizes

struct TruthTool {
  std::vector<Eigen::Vector3d> markers_in_tool;
  std::vector<double> diameters_mm;
  std::vector<double> cutoffs_rad;  // retro-reflection entrance cut-off of each marker's material
};

Eigen::Vector3d Vector3(const Json& j) {
  return {j.at(0).get<double>(), j.at(1).get<double>(), j.at(2).get<double>()};
}

Rigid3d Matrix(const Json& j) {
  Eigen::Matrix4d m;
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c)
      m(r, c) = j.at(static_cast<std::size_t>(r)).at(static_cast<std::size_t>(c)).get<double>();
  }
  return Rigid3d::FromMatrix(m);
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

OrderedJson StatsJson(const PoseErrorStats& s) {
  return {{"count", s.count},    {"median_mm", s.median_mm},   {"rms_mm", s.rms_mm},
          {"max_mm", s.max_mm},  {"median_deg", s.median_deg}, {"rms_deg", s.rms_deg},
          {"max_deg", s.max_deg}};
}

OrderedJson EvaluationJson(const std::string& name, const ToolEvaluation& e) {
  OrderedJson j{{"tool", name},
                {"frames", e.frames},
                {"posed_frames", e.posed_frames},
                {"fully_visible_frames", e.fully_visible_frames},
                {"tracked_fully_visible", e.tracked_fully_visible},
                {"tracked_fraction", e.tracked_fraction},
                {"wrong_identities", e.wrong_identities},
                {"raw", StatsJson(e.raw)},
                {"filtered", StatsJson(e.filtered)},
                {"raw_fully_visible", StatsJson(e.raw_fully_visible)},
                {"filtered_fully_visible", StatsJson(e.filtered_fully_visible)},
                {"static_frames", e.static_frames},
                {"jitter_raw_mm", e.jitter_raw_mm ? OrderedJson(*e.jitter_raw_mm) : OrderedJson()},
                {"jitter_filtered_mm",
                 e.jitter_filtered_mm ? OrderedJson(*e.jitter_filtered_mm) : OrderedJson()},
                {"range_bias", OrderedJson::array()}};
  for (const RangeBiasBin& b : e.range_bias) {
    j["range_bias"].push_back({{"from_mm", b.from_mm},
                               {"to_mm", b.to_mm},
                               {"mean_mm", b.mean_bias_mm},
                               {"count", b.count}});
  }
  return j;
}

void PrintText(const std::string& name, const ToolEvaluation& e) {
  const auto jitter = [](const std::optional<double>& j) {
    return j ? std::to_string(*j) + " mm" : std::string("n/a (no static run)");
  };
  std::cout << name << ": " << e.frames << " frames, posed " << e.posed_frames << ", tracked "
            << e.tracked_fully_visible << " of " << e.fully_visible_frames << " fully visible ("
            << 100.0 * e.tracked_fraction << " %), wrong identities " << e.wrong_identities << "\n"
            << "  raw      position median " << e.raw.median_mm << " RMS " << e.raw.rms_mm
            << " max " << e.raw.max_mm << " mm; rotation median " << e.raw.median_deg << " RMS "
            << e.raw.rms_deg << " max " << e.raw.max_deg << " deg\n"
            << "  raw, fully visible frames: position RMS " << e.raw_fully_visible.rms_mm
            << " mm, rotation RMS " << e.raw_fully_visible.rms_deg << " deg\n"
            << "  filtered, fully visible frames: position RMS " << e.filtered_fully_visible.rms_mm
            << " mm, rotation RMS " << e.filtered_fully_visible.rms_deg << " deg\n"
            << "  filtered position median " << e.filtered.median_mm << " RMS " << e.filtered.rms_mm
            << " max " << e.filtered.max_mm << " mm; rotation median " << e.filtered.median_deg
            << " RMS " << e.filtered.rms_deg << " max " << e.filtered.max_deg << " deg\n"
            << "  static jitter (" << e.static_frames << " frames): raw " << jitter(e.jitter_raw_mm)
            << ", filtered " << jitter(e.jitter_filtered_mm) << "\n  marker range bias:";
  for (const RangeBiasBin& b : e.range_bias) {
    std::cout << " " << b.from_mm << "-" << b.to_mm << " mm " << b.mean_bias_mm << " (" << b.count
              << ")";
  }
  std::cout << "\n";
}

int RunEvaluateTracking(int argc, char** argv) {
  CLI::App app{"Tracking accuracy of a poses file (tofnav track) against a simulation's truth.json",
               "tofnav evaluate tracking"};
  std::filesystem::path poses_path, truth_path;
  bool json = false;
  int min_pixels = 4;
  double wrong_deg = 10.0;
  TrackingEvaluationOptions options;
  app.add_option("poses", poses_path, "poses file (CSV or JSON) from tofnav track")->required();
  app.add_option("--truth", truth_path, "truth.json of the simulation")->required();
  app.add_option("--wrong-mm", options.wrong_translation_mm,
                 "a pose farther than this from the truth is a wrong identity [mm] (10)");
  app.add_option("--wrong-deg", wrong_deg, "... or turned by more than this [deg] (10)");
  app.add_option("--min-marker-pixels", min_pixels,
                 "pixels a marker needs to count as visible (4)");
  app.add_option("--jitter-warmup", options.jitter_warmup_frames,
                 "frames dropped at the start of each static run (20)");
  app.add_flag("--json", json, "print the figures as one JSON object");
  CLI11_PARSE(app, argc, argv);
  options.wrong_rotation_rad = wrong_deg * kDegToRad;

  const std::vector<ToolPoseRecord> records = ReadToolPoses(poses_path);
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

  std::vector<std::string> order;
  std::map<std::string, std::vector<ToolEvaluationFrame>> per_tool;
  for (const ToolPoseRecord& r : records) {
    if (!tools.contains(r.tool)) {
      throw std::runtime_error("tool '" + r.tool + "' of " + poses_path.string() + " is not in " +
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
    if (!per_tool.contains(r.tool)) order.push_back(r.tool);
    ToolEvaluationFrame e;
    e.true_ahat_from_tool = Matrix(f.at("ahat_from_" + r.tool));
    e.fully_visible =
        FullyVisible(f.at("visible_markers"), r.tool, tools[r.tool], tools, min_pixels);
    e.raw = r.ahat_from_tool;
    e.filtered = r.filtered_ahat_from_tool;
    per_tool[r.tool].push_back(e);
  }

  OrderedJson out{{"poses", poses_path.string()},
                  {"truth", truth_path.string()},
                  {"tools", OrderedJson::array()}};
  int wrong = 0;
  for (const std::string& name : order) {
    const ToolEvaluation e =
        EvaluateToolTracking(per_tool[name], tools[name].markers_in_tool, options);
    wrong += e.wrong_identities;
    if (json) {
      out["tools"].push_back(EvaluationJson(name, e));
    } else {
      PrintText(name, e);
    }
  }
  if (json) {
    out["wrong_identities"] = wrong;
    std::cout << out.dump(2) << "\n";
  } else {
    std::cout << "wrong identities over all tools: " << wrong << "\n";
  }
  return EXIT_SUCCESS;
}

[[maybe_unused]] const bool kRegistered =
    RegisterEvaluator({"tracking", "tool poses (tofnav track) against a simulation's truth.json",
                       RunEvaluateTracking});

}  // namespace
}  // namespace tofnav
