// SPDX-License-Identifier: BSD-3-Clause
// tofnav pivot: the instrument's tip by pivot calibration against a reference tool
// (docs/tracking.md, "Pivot calibration").
#include <CLI/CLI.hpp>
#include <cstdlib>
#include <iostream>
#include <nlohmann/json.hpp>
#include <numbers>

#include "commands.hpp"
#include "config_json.hpp"
#include "marker_source.hpp"
#include "progress.hpp"
#include "tofnav/casefile/marker_range_json.hpp"
#include "tofnav/casefile/tool_json.hpp"
#include "tofnav/core/units.hpp"
#include "tofnav/pipeline/marker_tasks.hpp"
#include "tofnav/tracking/pivot_calibration.hpp"

namespace tofnav {

int RunPivot(int argc, char** argv) {
  CLI::App app{
      "Pivot calibration: the instrument's tip (in its marker frame) from a recording in which "
      "the tip rests in a divot rigid with the reference while the instrument swings about it",
      "tofnav pivot"};
  AddConfigOptions(app);
  MarkerSourceArgs source_args;
  std::filesystem::path instrument_path, reference_path, marker_error_path, out_path;
  double min_range_deg = 30.0;
  bool quiet = false, json = false;
  source_args.AddTo(app);
  app.add_option("--tool", instrument_path, "instrument tool file (tool JSON or NDI .rom)")
      ->required();
  app.add_option("--reference", reference_path, "reference tool file the divot is rigid with")
      ->required();
  app.add_option("--marker-error", marker_error_path,
                 "f_rf curve (tofnav fit-marker-error) applied to marker ranges (Eq. 2)");
  app.add_option("--out", out_path, "instrument tool JSON written with tip_mm")->required();
  app.add_option("--min-range-deg", min_range_deg,
                 "refuse a recording whose shaft directions span less [deg]")
      ->check(CLI::Range(0.0, 180.0));
  app.add_flag("-q,--quiet", quiet, "no progress bar");
  app.add_flag("--json", json, "print the result as one JSON object");
  TOFNAV_PARSE(app, argc, argv);

  ToolGeometry instrument = ReadToolFile(instrument_path);
  const ToolGeometry reference = ReadToolFile(reference_path);
  if (instrument.name == reference.name) {
    throw std::runtime_error("the instrument and the reference are both called '" +
                             instrument.name + "'");
  }
  MarkerRangeModel model;
  if (!marker_error_path.empty()) model = ReadMarkerRangeJson(marker_error_path).model;
  ToolTrackerOptions tracking;
  tracking.filter_enabled = false;  // raw poses: a filter lags the swing
  const MarkerSource source = OpenMarkerSource(source_args);
  ProgressBar progress("pivot", quiet || json);
  const std::vector<ToolPoseRecord> records =
      TrackTools(source, source_args.detection, {reference, instrument}, tracking, model,
                 [&](std::size_t done, std::size_t total) { progress.Update(done, total); });
  std::vector<Rigid3d> reference_from_instrument;
  for (std::size_t i = 0; i + 1 < records.size(); i += 2) {
    const auto& r = records[i].ahat_from_tool;
    const auto& t = records[i + 1].ahat_from_tool;
    if (r && t) reference_from_instrument.push_back(r->Inverse() * *t);
  }
  PivotCalibrationOptions options;
  options.min_angular_range_rad = min_range_deg * std::numbers::pi / 180.0;
  const PivotCalibrationResult result = CalibratePivot(reference_from_instrument, options);
  const auto vector = [](const Eigen::Vector3d& v) { return nlohmann::json{v.x(), v.y(), v.z()}; };
  nlohmann::ordered_json summary{{"recording", source_args.recording.string()},
                                 {"frames", source.frames},
                                 {"poses", result.poses},
                                 {"outliers", result.outliers},
                                 {"status", ToString(result.status)},
                                 {"tip_mm", vector(result.tip_in_instrument)},
                                 {"pivot_in_reference_mm", vector(result.pivot_in_reference)},
                                 {"rms_mm", result.rms_mm},
                                 {"max_residual_mm", result.max_residual_mm},
                                 {"angular_range_deg", result.angular_range_rad * kRadToDeg}};
  if (result.status == PivotStatus::kOk) {
    instrument.tip_in_tool = result.tip_in_instrument;
    WriteToolJson(out_path, instrument);
    summary["out"] = out_path.string();
  }
  if (json) {
    std::cout << WithOptions(summary, app).dump(2) << "\n";
  } else {
    std::cout << "pivot calibration of '" << instrument.name << "' against '" << reference.name
              << "': " << result.poses << " poses of " << source.frames << " frames, "
              << result.outliers << " dropped as outliers\n"
              << "  tip " << summary["tip_mm"].dump() << " mm, pivot "
              << summary["pivot_in_reference_mm"].dump() << " mm in the reference\n"
              << "  RMS " << result.rms_mm << " mm, max " << result.max_residual_mm
              << " mm, angular range " << result.angular_range_rad * kRadToDeg << " deg\n";
  }
  switch (result.status) {
    case PivotStatus::kOk:
      if (!json) std::cout << "wrote " << out_path.string() << "\n";
      return EXIT_SUCCESS;
    case PivotStatus::kTooFewPoses:
      std::cerr << "tofnav pivot: error: " << result.poses << " frames with both tools posed, need "
                << options.min_poses << "; nothing written\n";
      return EXIT_FAILURE;
    case PivotStatus::kTooLittleRotation:
      std::cerr << "tofnav pivot: error: the shaft swung through "
                << result.angular_range_rad * kRadToDeg << " deg, need " << min_range_deg
                << " (swing the instrument further about its tip); nothing written\n";
      return EXIT_FAILURE;
  }
  return EXIT_FAILURE;
}

}  // namespace tofnav
