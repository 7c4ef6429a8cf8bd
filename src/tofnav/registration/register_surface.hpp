// SPDX-License-Identifier: BSD-3-Clause
// Surface registration of the CT skin to the reconstructed head (Sec. III-B): automatic coarse
// alignment, robust point-to-plane ICP, quality figures and refusal.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <span>

#include "tofnav/core/point_cloud.hpp"
#include "tofnav/core/rigid3d.hpp"
#include "tofnav/registration/coarse_alignment.hpp"
#include "tofnav/registration/icp.hpp"
#include "tofnav/registration/registration_quality.hpp"
#include "tofnav/registration/surface_index.hpp"

namespace tofnav {

struct RegisterSurfaceOptions {
  double sample_spacing_mm = 1.5;  // voxel subsampling of the reconstruction for the fine ICP
  /// Coarse candidates refined by the fine ICP; the best is kept and the next distinct one
  /// measures the ambiguity (RegistrationThresholds::max_ambiguity).
  int fine_candidates = 2;
  SurfaceIndexOptions source_normals;  // used only when the reconstruction has no normals
  CoarseAlignOptions coarse;
  IcpOptions icp;
  RegistrationThresholds thresholds;
  void Check() const;  // throws std::invalid_argument naming the field
};

struct RegisterSurfaceResult {
  /// Maps image (CT, LPS) points into the tool frame. Meaningful only when quality.accepted();
  /// kept when refused so that a report can show where the failed attempt ended.
  Rigid3d tool_from_image;
  RegistrationQuality quality;
  CoarseAlignResult coarse;  // not run (no candidates, hypotheses = 0) when a guess was given
  IcpResult icp;             // the chosen one, of image_from_tool: the reconstruction is the source
};

/// Registers the skin (image frame) to the reconstructed head surface (tool frame).
///
/// The partial reconstruction is the ICP *source* and the complete skin the *target*, so every
/// source point has a true counterpart (the paper moves the skin onto the reconstruction; the
/// optimum is the same, and the skin's KD-tree is built once per CT). The solution image_from_tool
/// is inverted into tool_from_image.
/// @param reconstruction_in_tool  points with outward normals (estimated by PCA when absent)
/// @param skin_in_image  the CT skin surface with outward normals
/// @param targets_in_image  plan targets where the TRE is predicted (may be empty)
/// @param tool_from_image_guess  skips the automatic coarse alignment when given
RegisterSurfaceResult RegisterSurface(const PointCloud& reconstruction_in_tool,
                                      const SurfaceIndex& skin_in_image,
                                      std::span<const Eigen::Vector3d> targets_in_image,
                                      const RegisterSurfaceOptions& options = {},
                                      const std::optional<Rigid3d>& tool_from_image_guess = {});

}  // namespace tofnav
