// SPDX-License-Identifier: BSD-3-Clause
// tofnav identify: patient-specific depth-error model from a sticker recording (Eq. 3-7).
#include "tofnav/pipeline/identify.hpp"

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>
#include <string>

#include "commands.hpp"
#include "config_json.hpp"
#include "head_region_option.hpp"
#include "identify_consensus_report.hpp"
#include "method_option.hpp"
#include "progress.hpp"
#include "tofnav/casefile/depth_model_json.hpp"
#include "tofnav/casefile/marker_range_json.hpp"
#include "tofnav/casefile/tool_json.hpp"
#include "tofnav/mesh/mesh_io.hpp"
#include "tofnav/recording/hl2ss_calibration.hpp"
#include "tofnav/recording/open_recording.hpp"
#include "tofnav/volume/volume_io.hpp"

namespace tofnav {
namespace {

// What the identification left out, in words: frames, points and marker observations (a marker
// in a frame), with the markers that lost observations.
void PrintLeftOut(const DepthModelFitReport& r) {
  std::cout << "  frames: " << r.frames_used << " used, " << r.frames_left_out
            << " left out with a hand or instrument in front of the head; "
            << r.head_points_left_out << " foreground head points removed\n"
            << "  markers: " << r.markers.size() << " seen in " << r.marker_observations
            << " observations; " << r.marker_observations_rejected
            << " observations left out as not on the skin, " << r.marker_patches_screened_out
            << " with foreground around them; " << r.marker_observations_curved
            << " markers on the head left out as too curved for a sticker (a tool's sphere)\n";
  for (std::size_t i = 0; i < r.markers.size(); ++i) {
    const StickerUse& m = r.markers[i];
    if (m.rejected == 0) continue;
    std::cout << "    marker " << i + 1 << " at (" << m.centre_mm[0] << ", " << m.centre_mm[1]
              << ", " << m.centre_mm[2] << ") mm: " << m.rejected << " of " << m.observations
              << " observations left out\n";
  }
}

// The start whose ranges made the skin's first placement kept.
std::string PlacedFrom(const IdentifyRecordingResult& r) {
  if (r.placement_kept < 0) return "none";
  return r.placement_candidates[static_cast<std::size_t>(r.placement_kept)].from;
}

}  // namespace

int RunIdentify(int argc, char** argv) {
  CLI::App app{
      "Identify the patient-specific depth-error model (paper Eq. 3-7) from a recording "
      "of the head with stick-on markers (docs/correction.md)",
      "tofnav identify"};
  AddConfigOptions(app);
  std::filesystem::path recording_path, calibration_path, ct_path, skin_path, frf_path, out_path;
  std::filesystem::path reference_tool_path;
  std::vector<std::filesystem::path> tool_paths;
  std::optional<double> sample_offset;
  int max_frames = 300, folds = 0, min_reference_markers = 6, placement_subsets = 3;
  std::optional<double> iso_hu;
  std::string angle_term = "theta";
  std::string form = "intensity";
  bool quiet = false, json = false;
  IdentificationSampling sampling;
  IdentificationOptions options;
  Method method = Method::kTofnav;
  AddMethodOption(app, method);
  app.add_option("recording", recording_path, "AHAT recording (hl2ss .bin or StreamRecorder)")
      ->required();
  app.add_option("--calibration", calibration_path, "hl2ss calibration folder")->required();
  app.add_option("--sample-offset", sample_offset, "calibration table sample offset (0 or 0.5)");
  auto* ct = app.add_option("--ct", ct_path, "pre-operative CT (NRRD, NIfTI, DICOM): Err_C");
  app.add_option("--skin", skin_path, "CT skin surface (PLY/STL/OBJ, image frame): Err_C")
      ->excludes(ct);
  app.add_option("--ct-skin-hu", iso_hu, "skin threshold [HU] (with --ct; unset: as tofnav skin)");
  app.add_option("--marker-error", frf_path, "f_rf JSON (Eq. 1) for marker pixels");
  app.add_option("--out", out_path, "depth_model.json to write")->required();
  app.add_option(
         "--tool", tool_paths,
         "tool JSON or NDI .rom (repeatable): its markers, tracked in each frame, are left out")
      ->check(CLI::ExistingFile);
  app.add_option("--reference-tool", reference_tool_path,
                 "tool rigid with the head (the headframe; JSON or .rom): with a CT, Err_C places "
                 "the skin once through its tracked pose and measures the head surface too")
      ->check(CLI::ExistingFile);
  app.add_option("--min-reference-markers", min_reference_markers,
                 "markers a frame's reference-tool pose needs to count, or all of a tool with "
                 "fewer (one plate of a two-plate headframe is too imprecise at the head)")
      ->check(CLI::PositiveNumber);
  bool raw_reference_rotation = false;
  app.add_flag("--raw-reference-rotation", raw_reference_rotation,
               "use each frame's measured reference-tool orientation (default: smoothed in world "
               "over the frames used, docs/correction.md 2)");
  app.add_option("--head-surface-weight", options.head_surface_weight,
                 "weight of the head samples' distances to the skin in Err_C (with "
                 "--reference-tool), relative to the markers'")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--joint-smoothness-weight", options.joint_smoothness_weight,
                 "weight of Err_S in Eq. (7) when Err_C runs through --reference-tool (1: the "
                 "paper's; docs/correction.md 2.11)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--max-frames", max_frames, "frames used, evenly spread")
      ->check(CLI::PositiveNumber);
  app.add_option("--placement-subsets", placement_subsets,
                 "the skin's first placement also tried from stage 1 on this many frame subsets; "
                 "0 = off (docs/correction.md 2.3)")
      ->check([](const std::string& v) {
        return v == "1" ? std::string("0 or at least 2") : std::string();
      })
      ->check(CLI::NonNegativeNumber);
  int consensus = 0;
  app.add_option("--consensus", consensus,
                 "identify again K times (2-10; 0 = off), each without another tenth of the "
                 "frames, and keep the weighted mean of the K + 1 models (docs/correction.md 2.9, "
                 "2.16; K + 1 times as long)")
      ->check([](const std::string& v) {
        return v == "1" ? std::string("0 (off) or 2 to 10") : std::string();
      })
      ->check(CLI::Range(0, 10));
  bool consensus_medoid = false;
  app.add_flag("--consensus-medoid", consensus_medoid,
               "with --consensus: keep the runs' medoid, not their weighted mean (the default: "
               "the mean moves less when a run is left out; docs/correction.md 2.16)");
  app.add_option("--model", angle_term, "angle term: theta (paper), theta2, 1-cos");
  std::vector<double> start_values;
  app.add_option("--start", start_values,
                 "start values C1 C2 C3 [C4] (unset: all 0; C2 must be 0 in the intensity form)")
      ->expected(3, 4);
  app.add_option("--form", form,
                 "terms: intensity = C1 + C3 g + C4 ln(AB_ref / AB) (default, docs/correction.md "
                 "2.1), paper = C1 + C2 d + C3 g (Eq. 3), paper+intensity = all four")
      ->check(CLI::IsMember({"intensity", "paper", "paper+intensity"}));
  std::vector<double> cyclic_values;
  app.add_option("--cyclic-error", cyclic_values,
                 "the sensor's cyclic range error A [mm] P [mm] phi [rad], held fixed "
                 "(docs/correction.md 2.2)")
      ->expected(3);
  bool uncentred = false;
  app.add_flag("--uncentred", uncentred,
               "keep the start's references (theta 0, AB_ref 130) instead of the head samples' "
               "medians: C1 as Eq. (3) writes it, poorly determined (docs/correction.md 2.7)");
  app.add_option("--fit-cyclic-error", options.fit_cyclic_period_mm,
                 "fit the sensor's cyclic range error at this period [mm] (e.g. 351.7 = L / 3) "
                 "with the coefficients: its amplitude and phase; 0: off (docs/correction.md 2.2)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--cross-validate", folds, "compare the model variants on K held-out blocks");
  app.add_option("--roi-radius-mm", sampling.segmentation.roi_radius_mm,
                 "head ROI around the markers' centroid [mm]");
  AddHeadRegionOption(app, sampling.segmentation.head_region);
  app.add_option("--transition-px", sampling.segmentation.transition_dilation_px,
                 "transitional band around markers, dropped [px]");
  app.add_option("--patch-radius-mm", sampling.patch_radius_mm,
                 "head points around a marker for its cubic surface [mm]");
  app.add_option("--ab-threshold", sampling.segmentation.marker_ab_threshold,
                 "marker AB threshold [counts]");
  app.add_option("--marker-thickness-mm", options.marker_thickness_mm,
                 "sticker thickness: markers lie this far outside the skin [mm]");
  app.add_option("--huber-mm", options.huber_scale_mm, "robust (Huber) scale [mm], 0 = off");
  app.add_option("--correctness-frames", options.max_correctness_frames,
                 "frames that run an ICP for Err_C");
  std::string multipath = "on";
  app.add_option("--multipath", multipath,
                 "remove one-bounce multipath before the fit (and, through the model file, before "
                 "every correction with it): on or off (docs/correction.md 7)")
      ->check(CLI::IsMember({"on", "off"}));
  app.add_option(
         "--ab-scale", sampling.multipath.ab_scale,
         "the illuminator's AB of an albedo-1 surface facing the camera at 1 m [counts m^2]")
      ->check(CLI::PositiveNumber);
  app.add_option("--multipath-source-stride-px", sampling.multipath.source_stride_px,
                 "multipath: one emitting patch per block of this many pixels")
      ->check(CLI::PositiveNumber);
  app.add_option("--multipath-receiver-stride-px", sampling.multipath.receiver_stride_px,
                 "multipath: indirect light computed every this many pixels, interpolated between")
      ->check(CLI::PositiveNumber);
  app.add_option("--multipath-passes", sampling.multipath.passes,
                 "multipath: passes of the fixed point (docs/correction.md 7)")
      ->check(CLI::PositiveNumber);
  app.add_option("--multipath-skin-delay-mm", sampling.multipath.skin_delay_mm,
                 "multipath: how long the skin reads from its subsurface delay, which the indirect "
                 "light picks up at each scattering (the paper's skin: 7.58; default 0: none; "
                 "docs/correction.md 7.3)")
      ->check(CLI::Range(0.0, 100.0));
  app.add_flag("--multipath-damped,!--multipath-undamped", sampling.multipath.damped,
               "multipath: damped fixed point, each pass from the mean of the last two (default)");
  bool allow_lossy_depth = false;
  app.add_flag("--allow-lossy-depth", allow_lossy_depth,
               "use SAME+H26x depth (4 mm steps, lossy) anyway (docs/ahat.md 3.6.5)");
  app.add_flag("-q,--quiet", quiet, "no progress bar");
  app.add_flag("--json", json, "print the result as JSON");
  TOFNAV_PARSE(app, argc, argv);
  if (consensus_medoid && consensus == 0) {
    std::cerr << "tofnav identify: --consensus-medoid needs --consensus K (2-10 runs to choose "
                 "from)\n";
    return EXIT_FAILURE;
  }
  sampling.multipath.enabled = multipath == "on";

  const AhatCamera camera(ReadHl2ssCalibration(calibration_path, sample_offset));
  const std::unique_ptr<AhatRecording> recording = OpenAhatRecording(recording_path);
  RefuseLossyDepth(*recording, recording_path, allow_lossy_depth);
  std::optional<MarkerRangeModel> frf;
  std::optional<StageCyclicErrorInfo> stage_cyclic;  // measured on the stage's plate, if it was
  if (!frf_path.empty()) {
    MarkerRangeFile file = ReadMarkerRangeJson(frf_path);
    frf = file.model;
    stage_cyclic = file.cyclic_error;
  }
  DepthErrorModel start;
  start.angle_term = ParseAngleTerm(angle_term);
  start.use_intensity = form != "paper";
  start.use_range_term = form != "intensity";
  if (!start_values.empty()) {
    start_values.resize(4, 0.0);
    start.c1_mm = start_values[0];
    start.c2 = start_values[1];
    start.c3_mm = start_values[2];
    start.c4_mm = start_values[3];
    if (!start.use_range_term && start.c2 != 0.0) {
      throw std::invalid_argument(
          "--start: C2 must be 0 in the intensity form (--form paper fits C2)");
    }
    start.Check();
  }
  if (!cyclic_values.empty()) {
    start.cyclic = {cyclic_values[0], cyclic_values[1], cyclic_values[2]};
    start.cyclic.Check();
  }
  // The device's cyclic error, measured on the f_rf stage's plate, is held unless the command
  // line gives or fits one (docs/correction.md 2.8).
  const bool cyclic_from_stage = stage_cyclic && cyclic_values.empty() &&
                                 options.fit_cyclic_period_mm == 0.0 && method != Method::kPaper;
  if (cyclic_from_stage) start.cyclic = stage_cyclic->cyclic;

  std::optional<SurfaceIndex> skin;
  if (!ct_path.empty()) skin.emplace(SkinIsoSurface(ReadVolume(ct_path), iso_hu));
  if (!skin_path.empty()) skin.emplace(ReadMesh(skin_path));
  IdentifyRecordingOptions identify;
  identify.max_frames = max_frames;
  identify.cross_validate_folds = folds;
  identify.start = start;
  identify.sampling = sampling;
  options.centre_references = !uncentred;
  identify.identification = options;
  for (const std::filesystem::path& p : tool_paths)
    identify.exclude_tools.push_back(ReadToolFile(p));
  if (!reference_tool_path.empty()) identify.reference_tool = ReadToolFile(reference_tool_path);
  identify.min_reference_markers = min_reference_markers;
  identify.placement_subsets = placement_subsets;
  identify.smooth_reference_rotation = !raw_reference_rotation;
  if (method == Method::kPaper) UsePaperIdentification(identify);
  ProgressBar progress("identify: frames", quiet || json);
  const IdentifyConsensusResult runs =
      IdentifyWithConsensus(*recording, camera, frf, skin ? &*skin : nullptr, identify, consensus,
                            [&](int run, int count, std::size_t done, std::size_t total) {
                              progress.Update(static_cast<std::size_t>(run) * total + done,
                                              static_cast<std::size_t>(count) * total);
                            });
  const IdentifyRecordingResult& result = runs.Kept();
  // The medoid's file with the runs' mean coefficients when asked (docs/correction.md 2.16).
  const bool mean_kept = !consensus_medoid && !runs.subsets.empty();
  DepthModelFile file = result.file;
  if (mean_kept) file.model = ConsensusMean(runs.Models());
  const nlohmann::ordered_json effective_options = EffectiveOptions(app);
  WriteDepthModelJson(out_path, file, &effective_options);
  nlohmann::ordered_json registration_report;
  if (result.reference_frame) {
    registration_report = {
        {"reference_frame", *result.reference_frame},
        {"icp_rmse_mm", result.icp_rmse_mm},
        {"icp_inlier_fraction", result.icp_inlier_fraction},
        {"placed_from", PlacedFrom(result)},
        {"merged_through", result.placed_through_tool ? "reference tool" : "world"},
        {"placement_candidates", nlohmann::ordered_json::array()}};
    for (const PlacementCandidate& c : result.placement_candidates) {
      registration_report["placement_candidates"].push_back(
          {{"from", c.from}, {"c1_mm", c.c1_mm}, {"inlier_fraction", c.inlier_fraction}});
    }
  }

  const DepthErrorModel& m = file.model;
  if (json) {
    nlohmann::ordered_json out{{"model", m.Name()},
                               {"c1_mm", m.c1_mm},
                               {"c2", m.c2},
                               {"c3_mm", m.c3_mm},
                               {"c4_mm", m.c4_mm},
                               {"theta_reference_rad", m.theta_reference_rad},
                               {"ab_reference", m.ab_reference},
                               {"cyclic_error", CyclicErrorToJson(m.cyclic)},
                               {"costs", m.report.costs},
                               {"multipath_removed", m.multipath.enabled},
                               {"frames", m.report.frames_used}};
    out["cyclic_error"]["fitted"] = options.fit_cyclic_period_mm > 0.0;
    out["cyclic_error"]["measured_on_stage"] = cyclic_from_stage;
    out.update(LeftOutToJson(m.report));
    nlohmann::ordered_json tools = nlohmann::ordered_json::object();
    for (const auto& [name, count] : result.tool_marker_observations_left_out) tools[name] = count;
    out["tool_marker_observations_left_out"] = tools;
    out["frames_with_tool_markers"] = result.frames_with_tool_markers;
    out["frames_with_reference_tool"] = result.frames_with_reference_tool;
    out["frames_reference_rotation_smoothed"] = result.frames_reference_rotation_smoothed;
    out.update(nlohmann::ordered_json{{"initial_cost_mm2", m.report.initial_cost},
                                      {"final_cost_mm2", m.report.final_cost},
                                      {"seconds", m.report.seconds},
                                      {"registration", registration_report},
                                      {"consensus", ConsensusToJson(runs, mean_kept)},
                                      {"cross_validation", nlohmann::ordered_json::object()},
                                      {"out", out_path.string()}});
    for (const auto& [name, cost] : m.report.cross_validation) {
      out["cross_validation"][name] = cost;
    }
    std::cout << WithOptions(out, app).dump(2) << "\n";
    return EXIT_SUCCESS;
  }
  std::cout << "model " << m.Name() << " (" << m.report.costs << ", " << m.report.frames_used
            << " frames, " << m.report.seconds << " s)\n"
            << "  C1 = " << m.c1_mm << " mm, C2 = " << m.c2 << ", C3 = " << m.c3_mm
            << " mm/unit, C4 = " << m.c4_mm << " mm\n"
            << "  C1 is the bias at theta_ref = " << m.theta_reference_rad
            << " rad, AB_ref = " << m.ab_reference << " (docs/correction.md 2.7)\n";
  if (m.cyclic.enabled()) {
    std::cout << "  cyclic error " << m.cyclic.amplitude_mm << " mm at period "
              << m.cyclic.period_mm << " mm, phase " << m.cyclic.phase_rad << " rad ("
              << (options.fit_cyclic_period_mm > 0.0 ? "fitted"
                  : cyclic_from_stage
                      ? "held: measured on the stage's plate, docs/correction.md 2.8"
                      : "held fixed")
              << ", docs/correction.md 2.2)\n";
  }
  std::cout << "  cost " << m.report.initial_cost << " -> " << m.report.final_cost << " mm^2\n"
            << "  multipath " << (m.multipath.enabled ? "removed first" : "not removed")
            << " (docs/correction.md 7)\n";
  PrintLeftOut(m.report);
  if (!reference_tool_path.empty()) {
    std::cout << "  reference tool measured in " << result.frames_with_reference_tool << " of "
              << m.report.frames_used + m.report.frames_left_out
              << " frames (Err_C placed the skin once through it: docs/correction.md 2), "
              << result.frames_reference_rotation_smoothed
              << " with its orientation smoothed in world\n";
  }
  if (result.reference_frame) {
    std::cout << "  skin first placed on head samples merged through "
              << (result.placed_through_tool ? "the reference tool" : "world") << ", with "
              << 100.0 * result.icp_inlier_fraction << " % of them within the ICP's gate (RMSE "
              << result.icp_rmse_mm << " mm; from the ranges of the " << PlacedFrom(result)
              << ", the best of " << result.placement_candidates.size()
              << " placements: docs/correction.md 2.3)\n";
    double lo = INFINITY, hi = -INFINITY;
    for (const PlacementCandidate& c : result.placement_candidates) {
      if (c.subset) {
        lo = std::min(lo, c.c1_mm);
        hi = std::max(hi, c.c1_mm);
      }
    }
    if (lo <= hi) {
      std::cout << "  stage 1 on frame subsets: C1 " << lo << " to " << hi << " mm (stage 1 on all "
                << "frames: " << result.placement_candidates.front().c1_mm << " mm)\n";
    }
  }
  for (const auto& [name, count] : result.tool_marker_observations_left_out) {
    std::cout << "  tool " << name << ": " << count
              << " marker observations left out before the sticker tests (in "
              << result.frames_with_tool_markers << " frames with any tool marker)\n";
  }
  for (const auto& [name, cost] : m.report.cross_validation) {
    std::cout << "  held-out Err_S^2 " << name << ": " << cost << " mm^2\n";
  }
  if (!runs.subsets.empty()) PrintConsensus(runs, mean_kept);
  std::cout << "wrote " << out_path.string() << "\n";
  return EXIT_SUCCESS;
}

}  // namespace tofnav
