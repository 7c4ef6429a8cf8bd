// SPDX-License-Identifier: BSD-3-Clause
// Fusion that checks each frame against the model fused so far (docs/reconstruction.md 1.2):
// a frame whose points do not lie on the model is rejected or its pose refined by a bounded
// point-to-plane alignment; pixels that contradict a well-observed surface are not fused.
#pragma once

#include <cstddef>

#include "tofnav/core/image.hpp"
#include "tofnav/core/rigid3d.hpp"
#include "tofnav/fusion/tsdf_volume.hpp"
#include "tofnav/sensor/ahat_camera.hpp"

namespace tofnav {

struct ModelCheckOptions {
  bool enabled = true;
  /// Frames fused before frames are checked: the model must exist first.
  int warmup_frames = 10;
  /// A voxel is part of the model when its accumulated weight reaches this (a frame adds <= 1):
  /// 10 observations average the 1 mm range noise to ~0.3 mm.
  double min_model_weight = 10.0;
  int pixel_stride = 4;  // frame pixels sampled for the residuals
  /// Fewer sampled points on the model: the frame sees mostly new surface; fused unchecked.
  std::size_t min_points = 200;
  /// Points within this band of the model surface are inliers [truncations]: beyond it the
  /// truncated distance says nothing about the offset.
  double inlier_band = 0.75;
  /// Fewer inliers among the points on the model: the frame contradicts it (a wrong pose) [0-1].
  double min_inlier_fraction = 0.5;
  /// Median |point-to-surface distance| of the inliers after alignment above this: rejected
  /// [mm]. Range noise of 1 mm gives ~0.7 mm; a 5 deg pose error several mm.
  double max_median_residual_mm = 1.5;
  /// Fuse with the aligned pose (else only judge with it). Off by default: on the suite the
  /// alignment mostly follows a view's own depth error, not a pose error, and refined frames
  /// bake it into the model (docs/reconstruction.md 5.2).
  bool refine = false;
  /// The alignment's bound: a frame offset further from the model is rejected (a rigid offset)
  /// [mm, rad at the points' centroid]. Tool tracking errs ~0.2 mm / 0.3 deg (docs/tracking.md).
  double max_correction_mm = 2.0;
  double max_correction_rad = 0.017453292519943295;  // 1 deg
  /// Smaller corrections are not applied (within the alignment's own noise) [mm, rad].
  double min_correction_mm = 0.05;
  double min_correction_rad = 0.00087266462599716477;  // 0.05 deg
  int iterations = 6;
  double huber_mm = 1.0;  // Huber threshold of the alignment's residuals
  /// Per-pixel gate: a pixel whose point lies gate_mm or more in front of a well-observed
  /// surface (an occluder such as a hand, a mixed pixel at its edge; in well-observed free space)
  /// or behind it (a range too long: multipath) is dropped instead of fused. The TSDF knows
  /// distances up to the truncation, so the gate is capped just below it; the default, one
  /// truncation at 1 mm voxels, measured better than 3 mm (docs/reconstruction.md 5.1): with a
  /// view-dependent multipath bias a tighter gate locks the surface to the first views.
  bool gate_pixels = true;
  double gate_mm = 4.0;
  void Check() const;  // throws PreconditionError naming the bad field
};

enum class ModelVerdict {
  kUnchecked,         // too little overlap with the model (or checks off): fused as is
  kAccepted,          // on the model: fused with its pose
  kRefined,           // fused with the aligned pose
  kRejectedResidual,  // too few inliers or too large a residual after alignment
  kRejectedOffset,    // the alignment needed more than the bound: a rigid offset
};
const char* ToString(ModelVerdict verdict);

struct ModelCheckResult {
  ModelVerdict verdict = ModelVerdict::kUnchecked;
  std::size_t points = 0;                 // sampled points on the model
  std::size_t inliers = 0;                // of which within the band (with the final pose)
  double median_residual_mm = 0.0;        // inliers' median |distance|, the tracked pose
  double median_residual_after_mm = 0.0;  // the same with the aligned pose
  /// tool_from_ahat to fuse with: correction * tracked (the tracked pose unless kRefined).
  Rigid3d tool_from_ahat;
  Rigid3d correction;          // refined_tool_from_tool
  double correction_mm = 0.0;  // at the points' centroid
  double correction_rad = 0.0;
};

/// Compares a frame (range cleaned and corrected, as it would be fused) posed by tool_from_ahat
/// with the model in `volume`: samples the TSDF at every pixel_stride-th pixel's point, aligns
/// the inliers point-to-plane to the model (Gauss-Newton, Huber, the distance divided by the
/// gradient's norm), and judges by ModelCheckOptions. Does not change the volume.
ModelCheckResult CheckFrameAgainstModel(const TsdfVolume& volume, const Image<float>& range_mm,
                                        const AhatCamera& camera, const Rigid3d& tool_from_ahat,
                                        const ModelCheckOptions& options);

/// The per-pixel gate (ModelCheckOptions::gate_pixels): sets to 0 the pixels of `range_mm`
/// whose point contradicts a well-observed surface; returns how many.
std::size_t GateInconsistentPixels(const TsdfVolume& volume, Image<float>& range_mm,
                                   const AhatCamera& camera, const Rigid3d& tool_from_ahat,
                                   const ModelCheckOptions& options);

struct CheckedIntegration {
  ModelCheckResult check;
  std::size_t pixels_gated = 0;
  bool fused = false;  // false when rejected
};

/// Checked fusion of one frame: once `volume` holds options.warmup_frames frames, the frame is
/// checked (CheckFrameAgainstModel) and, unless rejected, its pixels gated
/// (GateInconsistentPixels); then it is integrated with the pose the check gives.
CheckedIntegration IntegrateChecked(TsdfVolume& volume, Image<float> range_mm,
                                    const AhatCamera& camera, const Rigid3d& tool_from_ahat,
                                    const Image<float>& pixel_weight,
                                    const ModelCheckOptions& options);

}  // namespace tofnav
