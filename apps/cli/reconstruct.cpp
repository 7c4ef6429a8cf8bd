// SPDX-License-Identifier: BSD-3-Clause
// tofnav reconstruct: fuse a recording's frames, posed by the reference tool, into a surface.
#include "tofnav/pipeline/reconstruct.hpp"

#include <CLI/CLI.hpp>
#include <cstdlib>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <numbers>
#include <optional>
#include <vector>

#include "commands.hpp"
#include "config_json.hpp"
#include "head_region_option.hpp"
#include "method_option.hpp"
#include "progress.hpp"
#include "tofnav/casefile/depth_model_json.hpp"
#include "tofnav/casefile/marker_range_json.hpp"
#include "tofnav/casefile/tool_json.hpp"
#include "tofnav/core/require.hpp"
#include "tofnav/mesh/mesh_io.hpp"
#include "tofnav/pipeline/reconstruct_correction.hpp"
#include "tofnav/recording/open_recording.hpp"

namespace tofnav {
namespace {

Eigen::AlignedBox3d RoiFromList(const std::vector<double>& v) {
  Require(v.size() == 6, "--roi needs six numbers: xmin,ymin,zmin,xmax,ymax,zmax");
  const Eigen::Vector3d lo(v[0], v[1], v[2]), hi(v[3], v[4], v[5]);
  Require((hi.array() > lo.array()).all(), "--roi: each max must exceed its min");
  return {lo, hi};
}

nlohmann::ordered_json Vector(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

}  // namespace

int RunReconstruct(int argc, char** argv) {
  CLI::App app{
      "Fuse a recording's AHAT frames, posed by the tracked reference tool, into a TSDF in the "
      "tool frame and extract the surface as PLY (docs/reconstruction.md)",
      "tofnav reconstruct"};
  AddConfigOptions(app);
  std::filesystem::path recording_path, calibration_dir, tool_path, out_path, depth_model_path,
      marker_error_path;
  std::optional<double> sample_offset;
  std::vector<double> roi;
  bool quiet = false, json = false, all_components = false;
  std::optional<std::size_t> max_frames;
  ReconstructOptions options;
  Method method = Method::kTofnav;
  AddMethodOption(app, method);
  CorrectRangeOptions correct;
  double max_incidence_deg = 90.0;
  const std::map<std::string, TsdfWeighting> weightings = {
      {"constant", TsdfWeighting::kConstant}, {"incidence", TsdfWeighting::kIncidence}};
  app.add_option("recording", recording_path, "hl2ss .bin or StreamRecorder folder")->required();
  app.add_option("--calibration", calibration_dir,
                 "hl2ss calibration folder (unset: the recording's own, StreamRecorder)");
  app.add_option("--sample-offset", sample_offset, "calibration table sample offset (0 or 0.5)");
  app.add_option("--tool", tool_path, "reference tool JSON (the fusion frame)")->required();
  app.add_option("--out", out_path, "output surface (.ply, .stl or .obj), in the tool frame")
      ->required();
  app.add_option("--depth-model", depth_model_path,
                 "depth_model.json: correct surface ranges by Eq. (4) before fusion (its f_rf, if "
                 "any, also corrects the tool's marker ranges unless --marker-error is given)");
  app.add_option("--max-incidence-deg", max_incidence_deg,
                 "with --depth-model: drop pixels seen at a larger incidence (their Eq. (4) term "
                 "C3 theta rests on the least reliable normals)")
      ->check(CLI::Range(1.0, 90.0));
  app.add_option("--normal-smoothing-px", correct.normals.smoothing_radius_px,
                 "with --depth-model: range smoothing radius for the normals");
  app.add_option("--marker-error", marker_error_path,
                 "f_rf JSON: correct the tool's marker ranges by Eq. (2) for tracking");
  app.add_option("--roi", roi,
                 "region of interest in the tool frame: xmin,ymin,zmin,xmax,ymax,zmax")
      ->delimiter(',')
      ->expected(6);
  app.add_option("--voxel-mm", options.tsdf.voxel_size_mm, "voxel size [mm]");
  app.add_option("--truncation-vox", options.tsdf.truncation_vox, "truncation [voxels]");
  app.add_option("--max-weight", options.tsdf.max_weight, "running-average weight cap");
  AddEnumOption(app, "--weighting", options.tsdf.weighting, weightings, "constant or incidence");
  app.add_option("--ab-weight-reference", options.ab_weight_reference,
                 "weigh pixels by min(1, (AB / this)^2); 0 = off");
  app.add_option(
         "--multipath-weight-ratio", options.multipath_weight_ratio,
         "with a depth model that removes multipath: weigh pixels by 1 / (1 + (q / this)^2), "
         "q its predicted indirect-to-direct ratio; 0 = off")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--min-weight", options.mesh.min_weight,
                 "mesh only cells whose corners weigh more than this");
  app.add_option("--min-observed-frames", options.min_observed_frames,
                 "mesh only surface seen in at least this many frames (weight units)");
  app.add_option("--min-observed-fraction", options.min_observed_fraction,
                 "... and in at least this fraction of the frames fused (0 and 0: off)");
  app.add_option("--boundary-rings", options.boundary_rings_removed,
                 "rings of triangles taken off the surface's open boundaries (0: off)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--min-range-mm", options.tsdf.min_range_mm);
  app.add_option("--max-range-mm", options.tsdf.max_range_mm);
  app.add_option("--first-frame", options.first_frame);
  app.add_option("--every", options.frame_step, "fuse every n-th frame");
  app.add_option("--max-frames", max_frames, "consider at most N frames (after --every)");
  bool allow_lossy_depth = false;
  app.add_flag("--allow-lossy-depth", allow_lossy_depth,
               "use SAME+H26x depth (4 mm steps, lossy) anyway (docs/ahat.md 3.6.5)");
  app.add_flag("--all-components", all_components, "keep every connected component");
  bool all_markers = false;
  app.add_flag("--all-markers", all_markers,
               "fuse only frames in which every marker of the tool was matched (status ok)");
  bool no_model_check = false, refine = false, no_pixel_gate = false, no_pose_check = false,
       raw_rotation = false;
  app.add_flag("--no-model-check", no_model_check,
               "fuse every posed frame without checking it against the model fused so far");
  app.add_flag("--refine", refine,
               "fuse checked frames with their pose aligned to the model (default: the tracked "
               "pose; the alignment is only used to judge)");
  app.add_flag("--no-pixel-gate", no_pixel_gate,
               "fuse pixels that contradict a well-observed surface (occluders, multipath)");
  app.add_flag("--no-pose-check", no_pose_check,
               "keep frames whose world_from_tool jumps relative to their neighbours");
  app.add_flag("--raw-rotation", raw_rotation,
               "fuse each frame with the tool's measured orientation (default: smoothed in world "
               "over its neighbours within --smoothing-s, docs/reconstruction.md 1.1)");
  app.add_option("--smoothing-s", options.rotation_smoothing.half_window_s,
                 "half window of the orientation smoothing [s]")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--model-min-weight", options.model_check.min_model_weight,
                 "checks: a voxel is part of the model from this accumulated weight");
  app.add_option("--gate-mm", options.model_check.gate_mm,
                 "checks: pixels farther than this from a well-observed surface are dropped [mm]");
  double max_jump_deg = options.pose_consistency.max_rotation_rad * 180.0 / std::numbers::pi;
  app.add_option("--max-pose-jump-mm", options.pose_consistency.max_translation_mm,
                 "temporal check: largest distance of world_from_tool to its neighbours' median");
  app.add_option("--max-pose-jump-deg", max_jump_deg, "the same for rotation [deg]");
  AddHeadRegionOption(app, options.head_region);
  app.add_flag("-q,--quiet", quiet, "no progress bar");
  app.add_flag("--json", json, "print the summary as one JSON object");
  TOFNAV_PARSE(app, argc, argv);

  if (!roi.empty()) options.tsdf.roi_in_tool = RoiFromList(roi);
  options.max_frames = max_frames;
  options.largest_component = !all_components;
  options.accept_partially_occluded = !all_markers;
  options.model_check.enabled = !no_model_check;
  options.model_check.refine = refine;
  options.model_check.gate_pixels = !no_pixel_gate;
  options.check_pose_consistency = !no_pose_check;
  options.smooth_rotation = !raw_rotation;
  options.pose_consistency.max_rotation_rad = max_jump_deg * std::numbers::pi / 180.0;
  const RecordingWithCamera opened =
      OpenRecordingWithCamera(recording_path, calibration_dir, sample_offset);
  const AhatRecording& recording = *opened.recording;
  RefuseLossyDepth(recording, recording_path, allow_lossy_depth);
  const AhatCamera& camera = *opened.camera;
  // Before UseDepthModel, which hands the head region on to the range correction.
  if (method == Method::kPaper) UsePaperReconstruction(options);
  bool multipath_removed = false;  // the depth model says (docs/correction.md 7)
  if (!depth_model_path.empty()) {
    correct.max_incidence_rad = max_incidence_deg * std::numbers::pi / 180.0;
    const DepthModelFile model = ReadDepthModelJson(depth_model_path);
    multipath_removed = model.model.multipath.enabled;
    UseDepthModel(model, options, correct);
  }
  if (!marker_error_path.empty())
    options.marker_error = ReadMarkerRangeJson(marker_error_path).model;
  const ToolGeometry tool = ReadToolJson(tool_path);
  ProgressBar progress("reconstruct", quiet || json);
  const ReconstructResult r = ReconstructSurface(
      recording, camera, tool, options,
      [&](std::size_t done, std::size_t total) { progress.Update(done, total); });
  progress.Finish();
  WriteMesh(out_path, r.mesh);
  const double rate = r.total_s > 0.0 ? static_cast<double>(r.frames_considered) / r.total_s : 0.0;
  const double fuse_ms =
      r.frames_fused > 0 ? 1e3 * r.fuse_s / static_cast<double>(r.frames_fused) : 0.0;
  if (json) {
    nlohmann::ordered_json skipped = nlohmann::ordered_json::object();
    for (const auto& [status, count] : r.skipped_by_status) skipped[status] = count;
    nlohmann::ordered_json rejected = nlohmann::ordered_json::object();
    for (const auto& [reason, count] : r.rejected_by_reason) rejected[reason] = count;
    const nlohmann::ordered_json summary{
        {"out", out_path.string()},
        {"tool", tool.name},
        {"depth_model", depth_model_path.string()},
        {"multipath_removed", multipath_removed},
        {"marker_error", !options.marker_error.empty()},
        {"frames", r.frames_considered},
        {"frames_fused", r.frames_fused},
        {"frames_skipped", r.frames_skipped},
        {"skipped_by_status", skipped},
        {"frames_refined", r.frames_refined},
        {"frames_rejected", r.frames_rejected},
        {"rejected_by_reason", rejected},
        {"frames_model_checked", r.frames_model_checked},
        {"frames_pose_checked", r.frames_pose_checked},
        {"frames_rotation_smoothed", r.frames_rotation_smoothed},
        {"pixels_gated", r.pixels_gated},
        {"roi_min_mm", Vector(r.roi_in_tool.min())},
        {"roi_max_mm", Vector(r.roi_in_tool.max())},
        {"roi_automatic", r.roi_automatic},
        {"voxel_mm", options.tsdf.voxel_size_mm},
        {"truncation_mm", options.tsdf.truncation_mm()},
        {"blocks", r.blocks},
        {"vertices", r.mesh.vertices.size()},
        {"triangles", r.mesh.triangles.size()},
        {"vertices_before_component", r.mesh_vertices_before_component},
        {"mesh_min_weight", r.mesh_min_weight},
        {"vertices_seldom_observed", r.vertices_seldom_observed},
        {"vertices_at_boundary_removed", r.vertices_at_boundary_removed},
        {"read_s", r.read_s},
        {"track_s", r.track_s},
        {"prepare_s", r.prepare_s},
        {"fuse_s", r.fuse_s},
        {"fuse_ms_per_frame", fuse_ms},
        {"mesh_s", r.mesh_s},
        {"elapsed_s", r.total_s},
        {"frames_per_s", rate}};
    std::cout << WithOptions(summary, app).dump(2) << "\n";
    return EXIT_SUCCESS;
  }
  std::cout << "fused " << r.frames_fused << " of " << r.frames_considered << " frames ("
            << r.frames_skipped << " skipped: tool not ok) into " << r.blocks << " blocks; "
            << r.mesh.vertices.size() << " vertices, " << r.mesh.triangles.size()
            << " triangles -> " << out_path.string() << "\n"
            << "  checks: " << r.frames_refined << " refined, " << r.frames_rejected
            << " rejected (";
  const char* separator = "";
  for (const auto& [reason, count] : r.rejected_by_reason) {
    std::cout << separator << reason << " " << count;
    separator = ", ";
  }
  std::cout << "); " << r.frames_model_checked << " checked against the model, "
            << r.frames_pose_checked << " over time, " << r.frames_rotation_smoothed
            << " with the tool's orientation smoothed in world; " << r.pixels_gated
            << " pixels gated\n"
            << "  surface seen in fewer than " << r.mesh_min_weight
            << " frames left out: " << r.vertices_seldom_observed << " vertices; "
            << options.boundary_rings_removed
            << " rings off the boundary: " << r.vertices_at_boundary_removed << " vertices\n"
            << "  ROI (" << (r.roi_automatic ? "automatic" : "given") << ") ["
            << r.roi_in_tool.min().transpose() << "] - [" << r.roi_in_tool.max().transpose()
            << "] mm in " << tool.name << "\n"
            << "  multipath " << (multipath_removed ? "removed" : "not removed")
            << " before the depth model (docs/correction.md 7)\n"
            << "  " << r.total_s << " s (" << rate << " frames/s): fusion " << fuse_ms
            << " ms/frame, markers and ranges " << r.prepare_s << " s, poses " << r.track_s
            << " s, reading " << r.read_s << " s, meshing " << 1e3 * r.mesh_s << " ms\n";
  return EXIT_SUCCESS;
}

}  // namespace tofnav
