// SPDX-License-Identifier: BSD-3-Clause
// Beyond the paper: Eq. (5) with one skin placement for every frame, through the tracked
// reference tool, and the head surface itself measured against the skin (docs/correction.md 2).
#pragma once

#include <optional>
#include <span>
#include <vector>

#include "tofnav/core/rigid3d.hpp"
#include "tofnav/correction/depth_error_model.hpp"
#include "tofnav/correction/identification_frame.hpp"
#include "tofnav/correction/surface_costs.hpp"
#include "tofnav/registration/icp.hpp"
#include "tofnav/registration/surface_index.hpp"

namespace tofnav {

struct JointCorrectness {
  Rigid3d image_from_tool;  // the ICP result (the guess when it failed)
  bool converged = false;
  /// Per frame of `frame_indices` (same order), signed point-to-plane distances to the skin
  /// (outside > 0) [mm]: of its Eq. (2)-corrected marker points, and of its Eq. (4)-corrected
  /// head samples. Points with no skin sample within options.max_distance_mm count as that far.
  std::vector<std::vector<double>> marker_distances;
  std::vector<std::vector<double>> head_distances;
};

/// The head samples of the frames `frame_indices` (each must have tool_from_ahat), corrected
/// with `model` (Eq. 4), taken into the reference tool's frame through their tracked poses and
/// registered to the skin together by one point-to-plane ICP from `image_from_tool_guess`: a
/// per-frame ICP can absorb a constant depth offset into each frame's own translation, one rigid
/// placement for views from different directions cannot. The same transform places the marker
/// points. This is the frame in which `reconstruct` fuses the head. `icp_cache` carries the
/// ICP's nearest-neighbour answers from one call to the next on the same frames and skin (an
/// identification's evaluations): the figures are exactly those without it, only faster.
JointCorrectness JointCorrectnessDistances(std::span<const IdentificationFrame> frames,
                                           std::span<const int> frame_indices,
                                           const DepthErrorModel& model,
                                           const SurfaceIndex& skin_in_image,
                                           const Rigid3d& image_from_tool_guess,
                                           const CorrectnessOptions& options = {},
                                           IcpNeighbourCache* icp_cache = nullptr);

/// The rotation-averaged (chordal, by quaternions) and translation-averaged image_from_tool of
/// per-frame placements image_from_ahat_j * inverse(tool_from_ahat_j) (frames with a tool pose
/// only); nullopt when none has one.
std::optional<Rigid3d> MeanImageFromTool(std::span<const IdentificationFrame> frames,
                                         std::span<const int> frame_indices,
                                         std::span<const Rigid3d> image_from_ahat);

}  // namespace tofnav
