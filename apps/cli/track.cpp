// SPDX-License-Identifier: BSD-3-Clause
// tofnav track: per-frame poses of retro-reflective tools in a recording (docs/tracking.md).
#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>

#include "commands.hpp"
#include "config_json.hpp"
#include "marker_source.hpp"
#include "method_option.hpp"
#include "progress.hpp"
#include "tofnav/casefile/marker_range_json.hpp"
#include "tofnav/casefile/tool_json.hpp"
#include "tofnav/casefile/tool_poses_io.hpp"
#include "tofnav/core/statistics.hpp"
#include "tofnav/correction/marker_range_model.hpp"
#include "tofnav/pipeline/marker_tasks.hpp"

namespace tofnav {
namespace {

// The markers a tool's poses left out (docs/tracking.md section 6): per marker, posed frames in
// which it was dropped (by reason), used although damaged, or unseen.
nlohmann::ordered_json DropsJson(const ToolMarkerDrops& drops, std::size_t marker_count) {
  nlohmann::ordered_json j{{"posed_frames", drops.posed_frames},
                           {"frames_with_drops", drops.frames_with_drops},
                           {"observations_dropped", 0},
                           {"unchecked_frames", drops.unchecked_frames},
                           {"frames_with_void_refusals", drops.frames_with_void_refusals},
                           {"void_refusals", drops.void_refusals},
                           {"markers", nlohmann::ordered_json::array()}};
  std::int64_t dropped_total = 0;
  for (std::size_t k = 0; k < marker_count; ++k) {
    nlohmann::ordered_json marker{{"marker", k},
                                  {"used_damaged", 0},
                                  {"unseen", 0},
                                  {"dropped", nlohmann::ordered_json::object()}};
    if (k < drops.per_marker.size()) {
      for (const auto& [use, n] : drops.per_marker[k]) {
        if (use == MarkerUse::kUsedDamaged || use == MarkerUse::kUnseen) {
          marker[ToString(use)] = n;
        } else {
          marker["dropped"][ToString(use)] = n;
          dropped_total += n;
        }
      }
    }
    j["markers"].push_back(marker);
  }
  j["observations_dropped"] = dropped_total;
  return j;
}

// "  left out: marker 0 occluded 3, outlier 1; marker 2 merged 1 (in 4 of 90 posed frames)".
void PrintDrops(const nlohmann::ordered_json& drops) {
  std::cout << "    markers left out in " << drops["frames_with_drops"].get<std::int64_t>()
            << " of " << drops["posed_frames"].get<std::int64_t>() << " posed frames ("
            << drops["observations_dropped"].get<std::int64_t>() << " observations)";
  const char* separator = ": ";
  for (const auto& marker : drops["markers"]) {
    if (marker["dropped"].empty()) continue;
    std::cout << separator << "marker " << marker["marker"].get<std::size_t>();
    for (const auto& [reason, n] : marker["dropped"].items()) {
      std::cout << " " << reason << " " << n.get<std::int64_t>();
    }
    separator = "; ";
  }
  std::cout << "\n";
  if (drops["unchecked_frames"].get<std::int64_t>() > 0) {
    std::cout << "    " << drops["unchecked_frames"].get<std::int64_t>()
              << " posed frames had too few markers to check for a wrong one\n";
  }
  if (drops["void_refusals"].get<std::int64_t>() > 0) {
    std::cout << "    " << drops["void_refusals"].get<std::int64_t>() << " candidate poses in "
              << drops["frames_with_void_refusals"].get<std::int64_t>()
              << " frames refused: they put a marker where the image shows empty space\n";
  }
}

}  // namespace

int RunTrack(int argc, char** argv) {
  CLI::App app{
      "Track retro-reflective tools in an AHAT recording: one row per frame and tool "
      "with status, ahat_from_tool, world_from_tool, FRE (docs/tracking.md)",
      "tofnav track"};
  AddConfigOptions(app);
  MarkerSourceArgs source_args;
  std::vector<std::filesystem::path> tool_paths;
  std::filesystem::path marker_error_path, out_path;
  bool no_filter = false, ahat_filter = false, position_in_ahat = false, quiet = false,
       json = false;
  ToolTrackerOptions options;
  Method method = Method::kTofnav;
  AddMethodOption(app, method);
  source_args.AddTo(app);
  app.add_option("--tool", tool_paths, "tool file (tool JSON or NDI .rom); repeat per tool")
      ->required();
  app.add_option("--marker-error", marker_error_path,
                 "f_rf curve (tofnav fit-marker-error) applied to marker ranges (Eq. 2)");
  app.add_option("--out", out_path, "poses file: .csv or .json")->required();
  app.add_flag("--no-filter", no_filter, "no pose filter (filtered columns stay empty)");
  app.add_flag("--ahat-filter", ahat_filter,
               "filter the orientation in ahat even when frames carry a rig pose");
  app.add_flag("--position-in-ahat", position_in_ahat,
               "filter the position in ahat alone, not fused with the one held in the world "
               "(docs/tracking.md 1)");
  bool independent_rig_error = false;
  app.add_flag("--independent-rig-error", independent_rig_error,
               "fuse each tool's position with its own prediction alone, not with the rig "
               "pose's error shared by the frame's tools (docs/tracking.md 1)");
  app.add_option("--max-fre", options.pose.max_fre_mm, "FRE acceptance [mm]");
  bool keep_void_poses = false;
  app.add_flag("--keep-void-poses", keep_void_poses,
               "keep poses that put an unmatched marker where the image shows empty space");
  bool drop_damaged = false, no_outlier_check = false;
  app.add_flag("--drop-damaged", drop_damaged,
               "leave markers whose blob is occluded or touches another out of the pose when "
               "enough whole ones remain (default: kept; docs/tracking.md 6)");
  app.add_flag("--no-outlier-check", no_outlier_check,
               "no leave-one-out check of the markers' residuals (docs/tracking.md 6)");
  bool whole_blobs = false;
  app.add_flag("--whole-blobs", whole_blobs,
               "weigh every matched blob as a whole one, however much smaller than its tool's "
               "others (docs/tracking.md 6)");
  app.add_flag("-q,--quiet", quiet, "no progress bar");
  app.add_flag("--json", json, "print the summary as one JSON object");
  TOFNAV_PARSE(app, argc, argv);

  std::vector<ToolGeometry> tools;
  for (const std::filesystem::path& p : tool_paths) tools.push_back(ReadToolFile(p));
  for (std::size_t i = 0; i < tools.size(); ++i) {
    for (std::size_t j = 0; j < i; ++j) {
      if (tools[i].name == tools[j].name) {
        throw std::runtime_error("two tools are called '" + tools[i].name + "'");
      }
    }
  }
  MarkerRangeModel model;
  if (!marker_error_path.empty()) model = ReadMarkerRangeJson(marker_error_path).model;
  options.filter_enabled = !no_filter;
  options.rotation_in_world = !ahat_filter;
  options.position_in_world = !position_in_ahat;
  options.share_rig_error = !independent_rig_error;
  if (method == Method::kPaper) UsePaperTracking(options);
  options.pose.refuse_void_poses = !keep_void_poses;
  if (drop_damaged) options.pose.robust.drop_damaged = true;
  if (no_outlier_check) options.pose.robust.check_outliers = false;
  if (whole_blobs) options.pose.robust.truncation.enabled = false;
  const MarkerSource source = OpenMarkerSource(source_args);
  ProgressBar progress("track", quiet || json);
  const auto start = std::chrono::steady_clock::now();
  TrackingDrops drops;
  const std::vector<ToolPoseRecord> records = TrackTools(
      source, source_args.detection, tools, options, model,
      [&](std::size_t done, std::size_t total) { progress.Update(done, total); }, &drops);
  std::vector<std::map<ToolStatus, std::int64_t>> counts(tools.size());
  std::vector<std::vector<double>> fre(tools.size());
  for (std::size_t i = 0; i < records.size(); ++i) {
    const std::size_t t = i % tools.size();
    ++counts[t][records[i].status];
    if (records[i].ahat_from_tool) fre[t].push_back(records[i].fre_mm);
  }
  WriteToolPoses(out_path, records);
  const double elapsed_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  nlohmann::ordered_json summary{{"recording", source_args.recording.string()},
                                 {"out", out_path.string()},
                                 {"frames", source.frames},
                                 {"marker_error", !model.empty()},
                                 {"filter", options.filter_enabled},
                                 {"elapsed_s", elapsed_s},
                                 {"dropped_blobs", nlohmann::ordered_json::object()},
                                 {"tools", nlohmann::ordered_json::array()}};
  for (const auto& [reason, n] : drops.blobs) summary["dropped_blobs"][ToString(reason)] = n;
  for (std::size_t t = 0; t < tools.size(); ++t) {
    nlohmann::ordered_json tool{{"name", tools[t].name},
                                {"posed_frames", static_cast<std::int64_t>(fre[t].size())},
                                {"median_fre_mm", fre[t].empty() ? 0.0 : Median(fre[t])},
                                {"status", nlohmann::ordered_json::object()}};
    for (const auto& [status, n] : counts[t]) tool["status"][ToString(status)] = n;
    tool["marker_drops"] = DropsJson(drops.tools[t], tools[t].markers_in_tool.size());
    summary["tools"].push_back(tool);
  }
  if (json) {
    std::cout << WithOptions(summary, app).dump(2) << "\n";
    return EXIT_SUCCESS;
  }
  std::cout << "tracked " << tools.size() << " tool(s) over " << source.frames << " frames in "
            << elapsed_s << " s -> " << out_path.string() << "\n";
  for (const auto& tool : summary["tools"]) {
    std::cout << "  " << tool["name"].get<std::string>() << ": posed in "
              << tool["posed_frames"].get<std::int64_t>() << " frames, median FRE "
              << tool["median_fre_mm"].get<double>() << " mm;";
    for (const auto& [status, n] : tool["status"].items()) std::cout << " " << status << " " << n;
    std::cout << "\n";
    PrintDrops(tool["marker_drops"]);
  }
  if (!summary["dropped_blobs"].empty()) {
    std::cout << "  blobs dropped by detection (all frames):";
    for (const auto& [reason, n] : summary["dropped_blobs"].items()) {
      std::cout << " " << reason << " " << n.get<std::int64_t>();
    }
    std::cout << "\n";
  }
  return EXIT_SUCCESS;
}

}  // namespace tofnav
