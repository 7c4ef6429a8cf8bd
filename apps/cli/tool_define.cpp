// SPDX-License-Identifier: BSD-3-Clause
// tofnav tool-define: a tool's marker geometry from a recording of a static or moving tool.
#include <CLI/CLI.hpp>
#include <cstdlib>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "config_json.hpp"
#include "marker_source.hpp"
#include "progress.hpp"
#include "tofnav/casefile/marker_range_json.hpp"
#include "tofnav/casefile/tool_json.hpp"
#include "tofnav/correction/marker_range_model.hpp"
#include "tofnav/pipeline/marker_frames.hpp"
#include "tofnav/tracking/tool_definition.hpp"

namespace tofnav {

int RunToolDefine(int argc, char** argv) {
  CLI::App app{
      "Build a tool's marker geometry (tool JSON) from a recording of the tool alone, "
      "static or moving; flickering markers and stray blobs are tolerated",
      "tofnav tool-define"};
  AddConfigOptions(app);
  MarkerSourceArgs source_args;
  std::filesystem::path out_path, marker_error_path;
  std::vector<std::filesystem::path> other_paths;
  ToolDefinitionOptions options;
  bool quiet = false, json = false;
  const std::map<std::string, MarkerType> types = {{"sphere", MarkerType::kSphere},
                                                   {"flat", MarkerType::kDisc}};
  source_args.AddTo(app);
  app.add_option("--out", out_path, "tool JSON to write")->required();
  app.add_option("--name", options.name, "tool name");
  AddEnumOption(app, "--marker-type", options.marker_type, types, "sphere or flat");
  app.add_option("--marker-diameter", options.marker_diameter_mm, "marker diameter [mm]");
  app.add_option("--markers", options.marker_count,
                 "marker count (unset: the most frequent detection count)");
  app.add_option("--min-frames", options.min_frames, "frames that must match");
  app.add_option("--marker-error", marker_error_path, "f_rf curve applied to marker ranges");
  app.add_option("--other", other_paths,
                 "existing tool file(s) to compare with (minimum segment-length difference)");
  app.add_flag("-q,--quiet", quiet, "no progress bar");
  app.add_flag("--json", json, "print the report as one JSON object");
  TOFNAV_PARSE(app, argc, argv);

  std::vector<ToolGeometry> others;
  for (const std::filesystem::path& p : other_paths) others.push_back(ReadToolFile(p));
  MarkerRangeModel model;
  if (!marker_error_path.empty()) model = ReadMarkerRangeJson(marker_error_path).model;
  options.marker_entrance_gain_mm_per_rad = model.entrance_gain_mm_per_rad;
  const MarkerSource source = OpenMarkerSource(source_args);
  std::vector<std::vector<DetectedMarker>> frames(source.frames);
  ProgressBar progress("tool-define", quiet || json);
  ForEachFrameMarkers(
      source, source_args.detection,
      [&](std::size_t index, const AhatFrame&, std::vector<DetectedMarker>& markers) {
        frames[index] =
            model.empty() ? std::move(markers) : CorrectMarkerRanges(std::move(markers), model);
      },
      [&](std::size_t done, std::size_t total) { progress.Update(done, total); });
  progress.Finish();
  const ToolDefinitionResult result = DefineTool(frames, options);
  const ToolGeometryReport report = AnalyzeToolGeometry(result.tool, others);
  WriteToolJson(out_path, result.tool);

  nlohmann::ordered_json j{{"tool", result.tool.name},
                           {"out", out_path.string()},
                           {"markers", result.tool.markers_in_tool.size()},
                           {"frames", source.frames},
                           {"frames_used", result.frames_used},
                           {"frames_rejected", result.frames_rejected},
                           {"definition_rms_mm", result.definition_rms_mm},
                           {"marker_rms_mm", result.marker_rms_mm},
                           {"distances_mm", report.distances_mm},
                           {"min_distance_difference_mm", report.min_distance_difference_mm},
                           {"self_symmetry_fre_mm", report.self_symmetry_fre_mm},
                           {"planarity_rms_mm", report.planarity_rms_mm},
                           {"others", nlohmann::ordered_json::array()}};
  for (std::size_t o = 0; o < others.size(); ++o) {
    j["others"].push_back({{"tool", others[o].name},
                           {"min_segment_difference_mm", report.min_segment_difference_mm[o]},
                           {"confusion_fre_mm", report.confusion_fre_mm[o]}});
  }
  if (json) {
    std::cout << WithOptions(j, app).dump(2) << "\n";
    return EXIT_SUCCESS;
  }
  std::cout << "defined '" << result.tool.name << "' (" << result.tool.markers_in_tool.size()
            << " markers) from " << result.frames_used << " of " << source.frames
            << " frames, definition RMS " << result.definition_rms_mm << " mm -> "
            << out_path.string() << "\n  inter-marker distances [mm]:";
  const std::size_t n = result.tool.markers_in_tool.size();
  std::size_t k = 0;
  for (std::size_t a = 0; a < n; ++a) {
    for (std::size_t b = a + 1; b < n; ++b) {
      std::cout << " " << a << "-" << b << " " << report.distances_mm[k++];
    }
  }
  std::cout << "\n  min segment-length difference within the tool "
            << report.min_distance_difference_mm << " mm, self-symmetry FRE "
            << report.self_symmetry_fre_mm << " mm\n";
  for (std::size_t o = 0; o < others.size(); ++o) {
    std::cout << "  vs " << others[o].name << ": min segment-length difference "
              << report.min_segment_difference_mm[o] << " mm, confusion FRE "
              << report.confusion_fre_mm[o] << " mm\n";
  }
  return EXIT_SUCCESS;
}

}  // namespace tofnav
