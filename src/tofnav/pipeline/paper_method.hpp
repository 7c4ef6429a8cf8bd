// SPDX-License-Identifier: BSD-3-Clause
// The paper's method as published, as a baseline beside tofnav's on the same data (issue 38;
// docs/paper_method.md): each stage's options set to what Li et al. describe, with tofnav's
// additions turned off.
#pragma once

#include <cstdint>
#include <optional>
#include <string_view>

#include "tofnav/core/rigid3d.hpp"
#include "tofnav/pipeline/identify.hpp"
#include "tofnav/pipeline/navigator.hpp"
#include "tofnav/pipeline/reconstruct.hpp"
#include "tofnav/registration/register_surface.hpp"
#include "tofnav/tracking/tool_tracker.hpp"

namespace tofnav {

/// Which method a command runs: tofnav's (the default) or the paper's as published.
enum class Method { kTofnav, kPaper };
const char* ToString(Method method);  // "tofnav", "paper"
/// Inverse of ToString; nullopt on anything else.
std::optional<Method> ParseMethod(std::string_view name);

/// Eq. (3) with C1, C2 and C3 only (no intensity term, no cyclic error, no multipath removal),
/// identified by Eq. (7) on plain squares (Err_C registering each frame on its own, Err_S) from
/// the paper's segmentation: marker area by AB, its dilation as the transitional area, every other
/// pixel in the ROI the head (no head region, no tool markers blanked, no foreground screening, no
/// outlier stickers left out, one placement of the skin). Keeps max_frames and leave_out.
void UsePaperIdentification(IdentifyRecordingOptions& options);

/// Every tracked pose fused as it comes: no temporal pose check, no rotation smoothing, no
/// frame-versus-model check, no head region, no seldom-observed threshold or boundary erosion,
/// every pixel weighing 1, and the paper's tracking (UsePaperTracking). The ROI stays the
/// automatic one (the stand-in for the box the paper's user draws on one frame). The depth model
/// given with UseDepthModel (called after this) decides the range correction (a paper model
/// removes no multipath).
void UsePaperReconstruction(ReconstructOptions& options);

/// The on-device tracker the paper runs (Keller's, with f_rf on each marker, Sec. III-C): a
/// constant 4 mm pairwise-distance tolerance, markers may be occluded down to the tool's
/// minimum, the best candidate by its fit alone (no temporal prior), a Kabsch pose without the
/// anisotropic refinement or the damaged-marker and outlier checks, no check of unmatched
/// markers against empty space, and no pose filter. Detection (AB threshold, centroid, range
/// estimator) stays tofnav's.
void UsePaperTracking(ToolPoseOptions& options);
void UsePaperTracking(ToolTrackerOptions& options);
void UsePaperTracking(NavigatorOptions& options);

/// Point-to-plane ICP from the user's coarse placement (`tool_from_image_guess`), plain squares,
/// one 10 mm correspondence gate, no normal gate, and no refusal: the result is accepted
/// whatever its figures (the paper has no check).
void UsePaperRegistration(RegisterSurfaceOptions& options);

/// A hand placement in 3D Slicer as the paper's registration starts from it: the true
/// tool_from_image moved by `translation_mm` in a random direction and turned by `rotation_deg`
/// about a random axis through `centre_in_image` (the skin's centre), both drawn from `seed`.
Rigid3d HandPlacedStart(const Rigid3d& true_tool_from_image, const Eigen::Vector3d& centre_in_image,
                        std::uint64_t seed, double translation_mm = 5.0, double rotation_deg = 5.0);

}  // namespace tofnav
