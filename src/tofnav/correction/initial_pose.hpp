// SPDX-License-Identifier: BSD-3-Clause
// Where the CT skin is in each identification frame: one surface registration, then head poses.
#pragma once

#include <optional>
#include <span>
#include <vector>

#include "tofnav/core/rigid3d.hpp"
#include "tofnav/correction/depth_error_model.hpp"
#include "tofnav/correction/identification_frame.hpp"
#include "tofnav/registration/register_surface.hpp"
#include "tofnav/registration/surface_index.hpp"

namespace tofnav {

struct InitialPoseOptions {
  int merged_frames = 12;  // frames (with poses) merged into the reference frame's head cloud
  /// With at least this many frames holding a reference-tool pose (tool_from_ahat) and head
  /// samples, those frames are merged through the tool instead of through their rig poses.
  int min_tool_frames = 3;
  RegisterSurfaceOptions registration;
  void Check() const;  // throws std::invalid_argument naming the bad field
};

/// Where the skin is in the frame the head clouds were merged in: image_from_merged, with merged
/// the reference tool's frame (through_tool) or `world`. Runs on other frames of one recording
/// share it (docs/correction.md 2.13).
struct MergedPlacement {
  Rigid3d image_from_merged;
  bool through_tool = false;
};

/// True when two placements lie in different basins: their relative rotation is beyond
/// max_angle_rad or their relative translation beyond max_shift_mm (false when one is through the
/// tool and the other through `world`: they do not compare).
bool PlacementsDiffer(const MergedPlacement& a, const MergedPlacement& b,
                      double max_angle_rad = 0.05, double max_shift_mm = 5.0);

struct InitialPoseResult {
  /// image_from_ahat per frame (same order), nullopt for frames with neither pose.
  std::vector<std::optional<Rigid3d>> image_from_ahat;
  int reference_frame = -1;            // index into the frames
  bool through_tool = false;           // merged through the reference tool, not `world`
  RegisterSurfaceResult registration;  // of the reference frame (tool = its `ahat`)
  Rigid3d image_from_merged;           // the skin in the merged frame (tool or `world`)
};

/// The head samples of a few frames, corrected with `model`, are merged into the reference frame
/// (the one with the most head samples), registered to the skin by the registration module
/// (automatic coarse alignment + ICP) and propagated to every frame. With options.min_tool_frames
/// frames holding a reference-tool pose, they are merged through it and
/// image_from_ahat_j = image_from_tool * tool_from_ahat_j (the head is rigid with the tool, even
/// when the patient moves); otherwise the patient is taken as static in `world` (the paper's
/// set-up): image_from_ahat_j = image_from_world * world_from_ahat_j. Frames without the tool's
/// pose go through `world`. Throws std::invalid_argument when no frame has a pose and head
/// samples. With a `guess` merged the same way, the ICP starts from it instead of the coarse
/// search (a guess through the other frame is ignored).
InitialPoseResult InitialImageFromAhat(std::span<const IdentificationFrame> frames,
                                       const SurfaceIndex& skin_in_image,
                                       const DepthErrorModel& model,
                                       const InitialPoseOptions& options = {},
                                       const std::optional<MergedPlacement>& guess = {});

/// The placement kept among several starts.
struct BestStartPlacement {
  InitialPoseResult pose;
  int start = -1;  // index into the starts, then into the guesses (start - starts.size())
  std::vector<double> inlier_fractions;  // each start's placement's, then each guess's, in order
};

/// InitialImageFromAhat from each model in `starts` (in order); keeps the placement whose ICP
/// keeps the largest fraction of the merged cloud within its finest gate (the first on a tie).
/// A model far from the truth corrects the frames' ranges differently along their different
/// rays, so their clouds disagree and fewer points reach the skin; the coarse search can also
/// settle in a wrong basin from one start and not from another (docs/correction.md 2).
/// Each of `guesses` is refined from the first start's ranges and competes the same way.
/// Throws std::invalid_argument when `starts` is empty or no frame has a pose and head samples.
BestStartPlacement InitialImageFromBestStart(std::span<const IdentificationFrame> frames,
                                             const SurfaceIndex& skin_in_image,
                                             std::span<const DepthErrorModel> starts,
                                             const InitialPoseOptions& options = {},
                                             std::span<const MergedPlacement> guesses = {});

}  // namespace tofnav
