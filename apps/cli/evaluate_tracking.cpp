// SPDX-License-Identifier: BSD-3-Clause
// tofnav evaluate tracking: a poses file against the simulator's truth.json.
#include <CLI/CLI.hpp>
#include <cstdlib>
#include <iostream>
#include <nlohmann/json.hpp>
#include <numbers>

#include "config_json.hpp"
#include "evaluate.hpp"
#include "tofnav/casefile/tool_poses_io.hpp"
#include "tofnav/core/units.hpp"
#include "tofnav/evaluation/tracking_truth.hpp"

namespace tofnav {
namespace {

using OrderedJson = nlohmann::ordered_json;

OrderedJson StatsJson(const PoseErrorStats& s) {
  const Summary& mm = s.position_mm;
  const Summary& deg = s.rotation_deg;
  // rms_se_*: the RMS's sampling error over these frames (docs/statistics.md).
  return {{"count", mm.count},  {"median_mm", mm.median},
          {"rms_mm", mm.rms},   {"rms_se_mm", s.position_rms_se_mm},
          {"max_mm", mm.max},   {"median_deg", deg.median},
          {"rms_deg", deg.rms}, {"rms_se_deg", s.rotation_rms_se_deg},
          {"max_deg", deg.max}};
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
                // From a poses JSON (filtered_rotation_sd_deg): what navigation shows settled.
                {"filtered_settled_fully_visible", StatsJson(e.filtered_settled_fully_visible)},
                {"settling_frames", e.settling_frames},
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
            << "  raw      position median " << e.raw.position_mm.median << " RMS "
            << e.raw.position_mm.rms << " max " << e.raw.position_mm.max << " mm; rotation median "
            << e.raw.rotation_deg.median << " RMS " << e.raw.rotation_deg.rms << " max "
            << e.raw.rotation_deg.max << " deg\n"
            << "  raw, fully visible frames: position RMS " << e.raw_fully_visible.position_mm.rms
            << " mm, rotation RMS " << e.raw_fully_visible.rotation_deg.rms << " deg\n"
            << "  filtered, fully visible frames: position RMS "
            << e.filtered_fully_visible.position_mm.rms << " mm, rotation RMS "
            << e.filtered_fully_visible.rotation_deg.rms << " deg; less the " << e.settling_frames
            << " settling: rotation RMS " << e.filtered_settled_fully_visible.rotation_deg.rms
            << " deg\n"
            << "  filtered position median " << e.filtered.position_mm.median << " RMS "
            << e.filtered.position_mm.rms << " max " << e.filtered.position_mm.max
            << " mm; rotation median " << e.filtered.rotation_deg.median << " RMS "
            << e.filtered.rotation_deg.rms << " max " << e.filtered.rotation_deg.max << " deg\n"
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
  AddConfigOptions(app);
  std::filesystem::path poses_path, truth_path;
  bool json = false;
  int min_pixels = 4;
  double wrong_deg = 10.0;
  TrackingEvaluationOptions options;
  app.add_option("poses", poses_path, "poses file (CSV or JSON) from tofnav track")->required();
  app.add_option("--truth", truth_path, "truth.json of the simulation")->required();
  app.add_option("--wrong-mm", options.wrong_translation_mm,
                 "a pose farther than this from the truth is a wrong identity [mm]");
  app.add_option("--wrong-deg", wrong_deg, "... or turned by more than this [deg]");
  app.add_option("--min-marker-pixels", min_pixels, "pixels a marker needs to count as visible");
  app.add_option("--jitter-warmup", options.jitter_warmup_frames,
                 "frames dropped at the start of each static run");
  app.add_flag("--json", json, "print the figures as one JSON object");
  TOFNAV_PARSE(app, argc, argv);
  options.wrong_rotation_rad = wrong_deg * kDegToRad;

  const std::vector<ToolPoseRecord> records = ReadToolPoses(poses_path);
  const std::vector<ToolTruthEvaluation> evaluations =
      EvaluateTrackingAgainstTruth(records, truth_path, options, min_pixels);
  OrderedJson out{{"poses", poses_path.string()},
                  {"truth", truth_path.string()},
                  {"tools", OrderedJson::array()}};
  int wrong = 0;
  for (const ToolTruthEvaluation& t : evaluations) {
    wrong += t.evaluation.wrong_identities;
    if (json) {
      out["tools"].push_back(EvaluationJson(t.name, t.evaluation));
    } else {
      PrintText(t.name, t.evaluation);
    }
  }
  if (json) {
    out["wrong_identities"] = wrong;
    std::cout << WithOptions(out, app).dump(2) << "\n";
  } else {
    std::cout << "wrong identities over all tools: " << wrong << "\n";
  }
  return EXIT_SUCCESS;
}

[[maybe_unused]] const bool kTrackingRegistered =
    RegisterEvaluator({"tracking", "tool poses (tofnav track) against a simulation's truth.json",
                       RunEvaluateTracking});

}  // namespace
}  // namespace tofnav
