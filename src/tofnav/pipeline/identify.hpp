// SPDX-License-Identifier: BSD-3-Clause
// `tofnav identify` as one call: frames of a recording -> the patient-specific depth model
// (Eq. 3-7), smoothness first, then both costs against the CT skin (docs/correction.md).
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "tofnav/casefile/depth_model_json.hpp"
#include "tofnav/core/triangle_mesh.hpp"
#include "tofnav/correction/identification.hpp"
#include "tofnav/correction/identification_frame.hpp"
#include "tofnav/correction/initial_pose.hpp"
#include "tofnav/imaging/ct_volume.hpp"
#include "tofnav/markers/marker_detection.hpp"
#include "tofnav/registration/surface_index.hpp"
#include "tofnav/sensor/ahat_camera.hpp"
#include "tofnav/sensor/ahat_recording.hpp"
#include "tofnav/tracking/rotation_smoothing.hpp"
#include "tofnav/tracking/tool_geometry.hpp"

namespace tofnav {

/// Frames left out of the evenly spread ones, to measure how much the result depends on which
/// frames it saw (issue 40: 10 % left out, five subsets): the picked frame k is left out when
/// k % every == subset.
struct FrameLeaveOut {
  int subset = 0;
  int every = 10;
  void Check() const;  // throws std::invalid_argument: every >= 2, 0 <= subset < every
};

struct IdentifyRecordingOptions {
  int max_frames = 300;                    // frames used, evenly spread over the recording
  std::optional<FrameLeaveOut> leave_out;  // unset: every picked frame
  int cross_validate_folds = 0;  // >= 2: compare DefaultModelCandidates on held-out blocks
  /// Start values and variant (angle term, intensity, range term): the intensity form by
  /// default (docs/correction.md 2.1); a default-constructed DepthErrorModel is the paper's Eq. 3.
  DepthErrorModel start = IntensityFormModel();
  IdentificationSampling sampling;
  IdentificationOptions identification;
  /// Applied to each decoded frame before its preparation (e.g. to blank pixels); optional.
  std::function<void(AhatFrame&)> prepare_frame;
  /// Tracked tools (the headframe, instruments) whose markers must not be taken for skin
  /// stickers: in each frame their markers are located and matched as `tofnav track` does, and
  /// the pixels of every matched marker (its blob plus tool_marker_margin_px) are blanked before
  /// the preparation. The ring and curvature tests leave out most such markers but not all
  /// (docs/correction.md 2). Empty: no tracking.
  std::vector<ToolGeometry> exclude_tools;
  /// A tool rigid with the head (the headframe), tracked in each frame so that Err_C places the
  /// skin once through it (JointCorrectnessDistances, docs/correction.md 2). Unset: Err_C
  /// registers each frame on its own (the paper).
  std::optional<ToolGeometry> reference_tool;
  /// A frame's reference pose counts only with this many markers in it, or with all of them
  /// when the tool has fewer: one plate of a two-plate headframe tilts by tenths of a degree, a
  /// millimetre at the head 200 mm away, which the model then absorbs; a headframe of one plate
  /// counts whole, which beats leaving the head term out (both measured in docs/correction.md 2).
  int min_reference_markers = 6;
  /// The reference tool's orientation in each frame smoothed in `world` over its neighbours
  /// among the frames used (docs/correction.md 2): the per-frame tilt that Err_C's head term
  /// would take for depth error is averaged away. Frames without world_from_rig stay as measured.
  bool smooth_reference_rotation = true;
  RotationSmoothingOptions reference_rotation_smoothing;
  MarkerDetectionOptions detection;
  double tool_marker_margin_px = 6.0;  // beyond the blob's radius: its transitional band and more
  /// Beyond the paper: the skin's first placement is also made from stage 1 refitted on this many
  /// frame subsets (subset k leaves out every frame whose position is k modulo n), and the
  /// placement that keeps the most of the merged cloud within the ICP's finest gate is kept. The
  /// coarse search of one merged cloud can settle in a wrong basin on a last-bit change of its
  /// input, and stage 2 stays there (docs/correction.md 2.3). 0: stage 1's and the start
  /// model's placements only; otherwise at least 2.
  int placement_subsets = 3;
  /// Placements found by other runs on this recording (the consensus passes the best one,
  /// docs/correction.md 2.13): each is refined by ICP from stage 1's ranges and competes with
  /// the starts' placements on the same figure.
  std::vector<MergedPlacement> placement_guesses;
  /// Stage 2 starts from this model instead of stage 1's, and its ranges make one more first
  /// placement (the consensus passes the run of least cost when runs end in minima far apart,
  /// docs/correction.md 2.14). Unset: stage 1's model.
  std::optional<DepthErrorModel> joint_start;
};

/// One candidate for the skin's first placement: the model whose ranges made it and how much of
/// the merged cloud it kept.
struct PlacementCandidate {
  std::string from;     // "stage-1 model", "start model", "stage 1 without frames k mod n",
                        // "another run's placement"
  bool subset = false;  // stage 1 refitted on a frame subset
  double c1_mm = 0.0;
  double inlier_fraction = 0.0;
};

struct IdentifyRecordingResult {
  DepthModelFile file;  // the model (with its report) and the f_rf used
  /// With a skin: the registration that placed it (recording frame index, ICP figures).
  std::optional<int> reference_frame;
  double icp_rmse_mm = 0.0;
  double icp_inlier_fraction = 0.0;
  /// Every candidate placement in the order tried (stage 1, the start model, the subsets) and
  /// the one kept (an index into them).
  std::vector<PlacementCandidate> placement_candidates;
  int placement_kept = -1;
  bool placed_through_tool = false;  // frames merged through the reference tool, not `world`
  std::optional<MergedPlacement> placement;  // the first placement kept (with a skin)
  /// With exclude_tools: marker observations (a tool marker in a frame) blanked, per tool name,
  /// and the frames in which at least one was.
  std::vector<std::pair<std::string, std::int64_t>> tool_marker_observations_left_out;
  std::int64_t frames_with_tool_markers = 0;
  std::int64_t frames_with_reference_tool = 0;  // frames whose reference-tool pose was measured
  std::int64_t frames_reference_rotation_smoothed = 0;  // ... and smoothed in `world`
};

/// Prepares up to options.max_frames frames (markers corrected by `marker_range` when given),
/// identifies the model from smoothness alone, and with `skin` registers it once to head clouds
/// corrected by that model and identifies again with both costs (the CLI's and the demo's path).
/// `progress(done, total)` after each prepared frame. Throws std::invalid_argument when no frame
/// has a usable marker patch, IoError from the recording.
IdentifyRecordingResult IdentifyFromRecording(
    const AhatRecording& recording, const AhatCamera& camera,
    const std::optional<MarkerRangeModel>& marker_range, const SurfaceIndex* skin,
    const IdentifyRecordingOptions& options = {},
    const std::function<void(std::size_t, std::size_t)>& progress = {});

/// The CT skin for identification: imaging's ExtractSkin (as `tofnav skin`: the CT default
/// threshold unless `iso_hu` is given, largest component, cavities filled), in the image frame.
TriangleMesh SkinIsoSurface(const CtVolume& ct, std::optional<double> iso_hu = std::nullopt);

}  // namespace tofnav
