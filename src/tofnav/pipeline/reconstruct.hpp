// SPDX-License-Identifier: BSD-3-Clause
// `tofnav reconstruct`: tool-referenced TSDF fusion of a recording into a head surface (Sec.
// III-B).
#pragma once

#include <Eigen/Geometry>
#include <cstddef>
#include <functional>
#include <map>
#include <optional>
#include <span>
#include <string>

#include "tofnav/core/image.hpp"
#include "tofnav/core/triangle_mesh.hpp"
#include "tofnav/correction/head_region.hpp"
#include "tofnav/correction/marker_range_model.hpp"
#include "tofnav/fusion/marching_cubes.hpp"
#include "tofnav/fusion/model_check.hpp"
#include "tofnav/fusion/tsdf_volume.hpp"
#include "tofnav/markers/marker_detection.hpp"
#include "tofnav/sensor/ahat_camera.hpp"
#include "tofnav/sensor/ahat_recording.hpp"
#include "tofnav/tracking/pose_consistency.hpp"
#include "tofnav/tracking/rotation_smoothing.hpp"
#include "tofnav/tracking/tool_pose.hpp"

namespace tofnav {

/// A frame's corrected range: radial range of every pixel [mm], 0 = invalid or dropped, the
/// camera's size; and the multipath removal's indirect-to-direct ratio |q| per pixel (empty: none).
struct CorrectedRange {
  Image<float> range_mm;
  Image<float> indirect_ratio;
};
/// Whole-frame surface range correction (Eq. 4, e.g. correction::CorrectFrame). Empty: none.
using RangeCorrection =
    std::function<CorrectedRange(const AhatFrame& frame, const AhatCamera& camera)>;

/// The automatic region of interest (docs/reconstruction.md): on the first frame whose tool is
/// ok, the surface point seen by the central window of the image (median of its valid points in
/// `tool`; of all its valid points when the window has none) is the centre; the box bounds that
/// frame's points within `radius_mm` of the centre, grown by `margin_mm` on every side (the sides
/// seen later by a turning view). With ReconstructOptions::head_region enabled, the frame's range
/// holds only the head region, so the box bounds the head.
struct AutoRoiOptions {
  int centre_window_px = 48;  // side of the central pixel window
  double radius_mm = 150.0;   // points farther from the centre are background
  double margin_mm = 30.0;
  /// Posed frames whose centres vote: the ROI is centred on the median of their centre windows'
  /// medians, so one frame that looks elsewhere (a hand at the centre, the drape) cannot move it.
  int frames = 9;
  /// The mesh keeps the component with the most surface within this distance of the ROI's
  /// centre (ReconstructOptions::largest_component) [mm]: a head's front, not a fragment.
  double component_radius_mm = 60.0;
  void Check() const;  // throws PreconditionError naming the bad field
};

struct ReconstructOptions {
  TsdfOptions tsdf;  // voxel size, truncation, weights; tsdf.roi_in_tool is the ROI when set
  TsdfMeshOptions mesh;
  /// Surfaces seen in few frames are not meshed (docs/reconstruction.md 1.3): the marching cubes
  /// threshold is max(mesh.min_weight, min_observed_frames, min_observed_fraction x frames
  /// fused), in weight units (a frame adds <= 1 to a voxel), capped at half of tsdf.max_weight
  /// and of the frames fused.
  /// The rims of the observed region (mixed pixels at silhouettes, grazing views, a few frames'
  /// view-dependent error) are where the head's vertices beyond 3 mm lie. 0 and 0: off.
  double min_observed_frames = 5.0;
  double min_observed_fraction = 0.05;
  /// Rings of triangles taken off the surface's open boundaries after the component is chosen
  /// (ErodeBoundary, docs/reconstruction.md 1.3): what survives the threshold at a rim is still
  /// where the views graze and the few frames that see it disagree. 0: off.
  int boundary_rings_removed = 3;
  AutoRoiOptions auto_roi;  // used when tsdf.roi_in_tool is empty
  /// Automatic head region per frame (correction/head_region.hpp, the one identification uses):
  /// pixels outside it (headframe board, tool plates, fragments) are not fused. Disable for
  /// scenes whose objects are small or flat (test shapes on a platform).
  HeadRegionOptions head_region;
  MarkerDetectionOptions detection;
  ToolPoseOptions pose;
  MarkerRangeModel marker_error;  // f_rf (Eq. 2) for the tool's marker ranges; empty: none
  RangeCorrection correct_range;  // Eq. (4) on the surface pixels; empty: none
  /// Pixels at or above the marker AB threshold, dilated by this many pixels, are dropped from
  /// fusion: retro-reflective ranges and their transitional ring have another bias (Sec. III-A.5).
  int marker_mask_dilation_px = 3;
  /// Per-pixel weight min(1, (AB / ab_weight_reference)^2) (inverse ToF range variance, which
  /// scales with 1 / AB^2), floored at min_ab_weight; 0 = off (every pixel weighs 1).
  double ab_weight_reference = 0.0;
  double min_ab_weight = 0.05;
  /// Per-pixel weight 1 / (1 + (|q| / multipath_weight_ratio)^2), |q| the multipath removal's
  /// predicted indirect-to-direct ratio: its error grows with the light it removes, so each voxel
  /// leans on the views that carry the least of it (docs/reconstruction.md); 0 = off.
  double multipath_weight_ratio = 0.0;
  std::size_t first_frame = 0;
  std::size_t frame_step = 1;             // fuse every n-th frame
  std::optional<std::size_t> max_frames;  // frames considered (after the step)
  /// Keep one connected component: with the automatic ROI the one nearest its centre (what the
  /// wearer looked at: the head, not a larger drape or board beside it), else the largest.
  bool largest_component = true;
  /// Fuse frames whose tool was matched with min_visible or more but not all markers (status
  /// partially_occluded): a tool made of several rigidly joined ones is rarely seen whole.
  bool accept_partially_occluded = true;
  /// Checked fusion (docs/reconstruction.md 1.2): each frame against the model fused so far
  /// (rejected, or its pose refined), pixels that contradict a well-observed surface dropped.
  ModelCheckOptions model_check;
  /// Poses checked over time (docs/reconstruction.md 1.1): frames whose world_from_tool jumps
  /// relative to their neighbours are left out. Needs world_from_rig in the recording.
  bool check_pose_consistency = true;
  PoseConsistencyOptions pose_consistency;
  /// The tool's orientation smoothed in `world` over its neighbours (docs/reconstruction.md
  /// 1.1): the fusion frame's per-frame tilt noise, which the lever arm to the head turns into
  /// surface displacement, averaged away. Needs world_from_rig in the recording.
  bool smooth_rotation = true;
  RotationSmoothingOptions rotation_smoothing;
  void Check() const;  // throws PreconditionError naming the bad field
};

struct ReconstructResult {
  TriangleMesh mesh;  // in `tool` [mm]
  Eigen::AlignedBox3d roi_in_tool;
  bool roi_automatic = false;
  std::size_t frames_considered = 0;
  std::size_t frames_fused = 0;
  std::size_t frames_skipped = 0;  // no pose, or partially occluded when not accepted
  std::map<std::string, std::size_t> skipped_by_status;  // ToString(ToolStatus) -> frames
  /// Posed frames left out by the checks: "pose_jump" (temporal check), "model_residual" and
  /// "model_offset" (ModelVerdict); not in frames_skipped.
  std::size_t frames_rejected = 0;
  std::map<std::string, std::size_t> rejected_by_reason;
  std::size_t frames_refined = 0;            // fused with the pose aligned to the model
  std::size_t frames_model_checked = 0;      // judged against the model (the rest: too early or
                                             // too little overlap)
  std::size_t frames_pose_checked = 0;       // judged by the temporal check
  std::size_t frames_rotation_smoothed = 0;  // fused with the orientation smoothed in `world`
  std::size_t pixels_gated = 0;              // dropped by the per-pixel gate, all frames
  std::size_t blocks = 0;                    // allocated 8^3 blocks
  std::size_t mesh_vertices_before_component = 0;  // marching cubes output
  double mesh_min_weight = 0.0;  // the threshold used (min_observed_frames, _fraction)
  /// Marching-cubes vertices left out as seen in too few frames (before the component).
  std::size_t vertices_seldom_observed = 0;
  std::size_t vertices_at_boundary_removed = 0;  // by boundary_rings_removed (after the component)
  double read_s = 0.0;                           // decoding frames
  double prepare_s = 0.0;  // markers, f_rf, range cleaning, Eq. (4), AB weights (in parallel)
  double track_s = 0.0;    // tool poses and the temporal check
  double fuse_s = 0.0;     // model checks, pixel gates and TsdfVolume::Integrate
  double mesh_s = 0.0;     // marching cubes + largest component
  double total_s = 0.0;
};

/// Per frame (from first_frame, every frame_step-th): markers (f_rf-corrected when given), the
/// tool's pose (unfiltered; frames without one are skipped and counted), the temporal pose check
/// over all frames; then per posed frame the camera pose tool_from_ahat, range cleaned (markers
/// masked) and corrected, checked against the model and fused in `tool`; then marching cubes
/// and the largest connected component. Deterministic for any thread count.
/// Throws PreconditionError on bad options, IoError from the recording, and std::runtime_error
/// when no frame has the tool (automatic ROI impossible) or nothing was reconstructed.
ReconstructResult ReconstructSurface(
    const AhatRecording& recording, const AhatCamera& camera, const ToolGeometry& tool,
    const ReconstructOptions& options = {},
    const std::function<void(std::size_t, std::size_t)>& progress = {});

/// The marching-cubes weight threshold ReconstructSurface uses after fusing `frames_fused`
/// frames: max(mesh.min_weight, min_observed_frames, min_observed_fraction x frames_fused),
/// capped at max(mesh.min_weight, min(tsdf.max_weight, frames_fused) / 2) (docs/reconstruction.md
/// 1.3). A cell is meshed when its corners weigh more than this.
double SeldomObservedMinWeight(const ReconstructOptions& options, std::size_t frames_fused);

/// One posed range image for the automatic ROI.
struct RoiView {
  const Image<float>* range_mm = nullptr;
  Rigid3d tool_from_ahat;
};

/// The automatic ROI of posed range images (AutoRoiOptions): centred on the component-wise
/// median of each view's centre (the median of its central window's points in `tool`, or of all
/// its points when that window is empty), bounding the points within radius_mm of it of the
/// view whose own centre is nearest (the most typical view, as one frame chose it before), plus
/// the margin. nullopt when no view has a valid range. `centre_in_tool`, when given, gets
/// that centre (a point on what the wearer looked at).
std::optional<Eigen::AlignedBox3d> AutomaticRoi(std::span<const RoiView> views,
                                                const AhatCamera& camera,
                                                const AutoRoiOptions& options = {},
                                                Eigen::Vector3d* centre_in_tool = nullptr);

}  // namespace tofnav
