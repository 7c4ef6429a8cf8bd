// SPDX-License-Identifier: BSD-3-Clause
// What the identification leaves out before it fits (docs/correction.md, "Screening"): head
// points of transient foreground objects (a hand, an instrument passing between the headset and
// the head), the frames they dominate, and which sticker each marker patch belongs to.
#pragma once

#include <span>
#include <vector>

#include "tofnav/correction/depth_error_model.hpp"
#include "tofnav/correction/identification_frame.hpp"

namespace tofnav {

struct ForegroundScreeningOptions {
  bool enabled = true;
  /// Cells of the world grid that counts, per cell, the frames whose head points fall in it or
  /// in its 26 neighbours [mm]. 8 mm cells see ~6 of a frame's 500 samples per neighbourhood.
  double cell_mm = 8.0;
  /// A neighbourhood is well observed when at least this fraction of the posed frames (and at
  /// least min_support_frames) have a head point in it.
  double min_support_fraction = 0.25;
  int min_support_frames = 3;
  /// A poorly observed point is foreground when a well-observed neighbourhood lies behind it
  /// along its ray, from 2 cells to this far behind [mm]: it hides a surface the other frames see.
  double behind_search_mm = 100.0;
  /// Frames whose head points are more than this fraction foreground are left out whole.
  double max_frame_foreground_fraction = 0.15;
  /// A marker patch whose neighbours are more than this fraction foreground is left out.
  double max_patch_foreground_fraction = 0.10;
  void Check() const;  // throws std::invalid_argument naming the bad field
};

/// Counts of what ScreenForeground left out.
struct ForegroundScreeningReport {
  int frames_in = 0;
  int frames_without_world_pose = 0;  // not screened (no rig pose: nothing to compare in world)
  int frames_left_out = 0;            // dominated by foreground
  int head_points_left_out = 0;       // foreground points removed from the frames kept
  int marker_patches_left_out = 0;    // patches whose surroundings were foreground
};

/// The frames without their foreground: each frame's head samples and patch neighbours,
/// corrected by `model` (Eq. 4) and placed in `world` by the frame's rig pose, are compared with
/// every other posed frame's. A point that few frames see, in front of a surface that many frames
/// see, is a transient object between the camera and the head, not skin. Frames without a world
/// pose pass unchanged (counted).
std::vector<IdentificationFrame> ScreenForeground(std::span<const IdentificationFrame> frames,
                                                  const DepthErrorModel& model,
                                                  const ForegroundScreeningOptions& options,
                                                  ForegroundScreeningReport& report);

/// Groups marker observations (patch `k` of frame `f`) into physical markers: observations whose
/// centres (mean of the marker points) lie within `radius_mm` in `world` are the same marker.
/// Returns the marker id of every observation, per frame and patch, and fills `markers` (their
/// centres and observation counts; `rejected` left 0).
std::vector<std::vector<int>> GroupMarkerObservations(std::span<const IdentificationFrame> frames,
                                                      double radius_mm,
                                                      std::vector<StickerUse>& markers);

/// How far a marker patch's median Eq. (6) distance may lie from the other patches' before the
/// patch is left out: beyond max(spreads x 1.4826 MAD, min_mm), after the sticker's thickness.
struct MarkerOutlierLimits {
  double thickness_mm = 0.0;
  double spreads = 3.0;
  double min_mm = 2.0;
};

/// The frames without the marker patches whose median Eq. (6) distance under `model` lies far
/// from every other patch's: markers that are not on the skin (a tool's marker on its plate, whose
/// unbiased surroundings the skin model over-corrects by the whole skin bias; a sticker on hair).
/// A bounded (Huber) loss still pulls a little on each of them, always the same way.
/// `rejected[f][k]` says whether patch k of frame f was left out.
std::vector<IdentificationFrame> WithoutOutlierMarkers(std::span<const IdentificationFrame> frames,
                                                       const DepthErrorModel& model,
                                                       const MarkerOutlierLimits& limits,
                                                       std::vector<std::vector<char>>& rejected);

}  // namespace tofnav
