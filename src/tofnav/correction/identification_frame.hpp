// SPDX-License-Identifier: BSD-3-Clause
// The samples of one frame that the identification (Eq. 5-7) needs, extracted once per frame.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <optional>
#include <span>
#include <utility>
#include <vector>

#include "tofnav/core/point_cloud.hpp"
#include "tofnav/core/rigid3d.hpp"
#include "tofnav/correction/depth_error_model.hpp"
#include "tofnav/correction/frame_segmentation.hpp"
#include "tofnav/correction/intensity_ab.hpp"
#include "tofnav/correction/marker_range_model.hpp"
#include "tofnav/correction/range_normals.hpp"
#include "tofnav/markers/marker_detection.hpp"
#include "tofnav/sensor/ahat_camera.hpp"
#include "tofnav/sensor/ahat_frame.hpp"

namespace tofnav {

/// One head-surface pixel: what Eq. (4) needs to correct it.
struct SurfaceSample {
  Eigen::Vector3f ray = Eigen::Vector3f::UnitZ();  // unit ray in `ahat`
  float range_mm = 0.0f;                           // measured
  float incidence_rad = 0.0f;                      // theta from the measured normal
  float ab = 0.0f;                                 // counts
};

/// One marker with the head surface around it (Eq. 6).
struct MarkerPatch {
  Points3d marker_points;                 // Eq. (2)-corrected marker points in `ahat` [mm]
  std::vector<SurfaceSample> neighbours;  // head pixels within the patch radius
  /// Fixed local frame of the cubic surface, from the measured neighbours: origin at their
  /// centroid, z along their least-variance axis; x, y scaled by 1 / patch radius.
  Eigen::Matrix3d local_from_ahat = Eigen::Matrix3d::Identity();
  Eigen::Vector3d origin_in_ahat = Eigen::Vector3d::Zero();
  double scale_mm = 1.0;
};

struct IdentificationFrame {
  int index = 0;  // in the recording
  std::vector<MarkerPatch> markers;
  std::vector<SurfaceSample> head;         // subsampled head surface for the ICP of Err_C (Eq. 5)
  Points3d marker_points;                  // every marker's Eq. (2)-corrected points, `ahat` [mm]
  std::optional<Rigid3d> world_from_ahat;  // from the frame's rig pose, when it has one
  /// The reference tool's (a tool rigid with the head) tracked pose, inverted, when tracked: Err_C
  /// then places the skin once for all frames (JointCorrectnessDistances).
  std::optional<Rigid3d> tool_from_ahat;
  int curved_markers = 0;  // markers on the head left out as too curved
};

struct IdentificationSampling {
  SegmentationOptions segmentation = {.roi_radius_mm = 130.0};
  RangeNormalOptions normals;
  double patch_radius_mm = 30.0;  // head points around a marker for its cubic surface
  int min_patch_points = 40;      // fewer: the marker is left out of Err_S
  int max_patch_points = 160;     // evenly subsampled beyond
  int max_marker_points = 48;     // per marker
  /// A sticker's points (Eq. 5 and 6) are its core pixels, AB >= this fraction of its peak
  /// (dimensionless), as the tracker takes a marker's range and the stage measured f_rf
  /// (docs/tracking.md 9.2): a rim pixel mixes the skin's light, long by the skin's own delay and
  /// its multipath, into the sticker's (docs/correction.md 2.15). 0: every pixel.
  double marker_core_ab_fraction = MarkerDetectionOptions{}.core_ab_fraction;
  int max_head_points = 500;  // per frame, for the ICP
  /// Markers count (Eq. 5 and 6) only when at least this fraction of a ring marker_ring_px wide
  /// just outside their transitional band is head: stickers on the skin, not a tool's markers.
  int marker_ring_px = 3;
  double min_marker_head_fraction = 0.5;
  /// A sticker follows the skin; a tool's sphere seen against the skin does not. Markers whose
  /// Eq. (2)-corrected points bend more than this (k of z = k (x^2 + y^2) in their own plane,
  /// k = 1 / (2 R): 0.04 is a radius of curvature of 12.5 mm) are left out [1/mm]. Measured on
  /// a suite case: stickers <= 0.03, 11.5 mm spheres >= 0.055 (docs/correction.md 2).
  double max_sticker_curvature_per_mm = 0.04;
  /// Outliers (judged on the measured points) lie beyond max(3 x 1.4826 MAD, this) [mm].
  double min_outlier_mm = 1.5;
  /// theta of the patch neighbours from the cubic surface fitted to them (SetIncidenceFromPatch-
  /// Surface) instead of per-pixel normals: unbiased by the range noise.
  bool incidence_from_patch_surface = true;
  /// One-bounce multipath removed from the surface range before sampling (docs/correction.md 7);
  /// the identified model carries these options so that correction prepares ranges the same way.
  MultipathCorrectionOptions multipath;
  /// The AB the samples carry for the intensity term, read as CorrectFrame reads it.
  IntensityAbOptions intensity_ab;
  void Check() const;  // throws std::invalid_argument naming the bad field
};

/// Segments the frame, corrects marker pixels with Eq. (2) and samples the head surface (with
/// theta from normals of the surface-only range). Never throws on frame content.
IdentificationFrame PrepareIdentificationFrame(const AhatFrame& frame, const AhatCamera& camera,
                                               const MarkerRangeModel& marker_model, int index,
                                               const IdentificationSampling& sampling = {});

/// PrepareIdentificationFrame of read(indices[i]) for every i: frames read in order on the
/// calling thread (a recording reader need not be thread-safe), prepared in parallel batches;
/// progress(done, total) after each batch. The CLI's and the benchmark's path.
std::vector<IdentificationFrame> PrepareIdentificationFrames(
    std::span<const int> indices, const std::function<AhatFrame(int)>& read,
    const AhatCamera& camera, const MarkerRangeModel& marker_model,
    const IdentificationSampling& sampling = {},
    const std::function<void(std::size_t, std::size_t)>& progress = {});

/// The corrected point of a sample under `model` (Eq. 4) [mm].
Eigen::Vector3d CorrectedPoint(const SurfaceSample& sample, const DepthErrorModel& model);

/// Indices of at most `max_count` of `count` items, evenly spread (all when count <= max_count).
std::vector<int> EvenSubsample(int count, int max_count);

/// Median and robust spread (1.4826 x median absolute deviation) of the values; (0, 0) when empty.
std::pair<double, double> MedianSpread(std::vector<double> values);

}  // namespace tofnav
