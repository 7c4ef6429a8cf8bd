// SPDX-License-Identifier: BSD-3-Clause
// Depth correction of a whole AHAT frame: Eq. (4) on the head surface, Eq. (2) on markers.
#pragma once

#include "tofnav/core/image.hpp"
#include "tofnav/correction/depth_error_model.hpp"
#include "tofnav/correction/frame_segmentation.hpp"
#include "tofnav/correction/intensity_ab.hpp"
#include "tofnav/correction/marker_range_model.hpp"
#include "tofnav/correction/range_normals.hpp"
#include "tofnav/sensor/ahat_camera.hpp"
#include "tofnav/sensor/ahat_frame.hpp"

namespace tofnav {

struct CorrectRangeOptions {
  MarkerRangeModel marker_model;  // f_rf for marker pixels (empty: markers kept as measured)
  SegmentationOptions segmentation;
  RangeNormalOptions normals;
  /// Keep only head-surface and marker pixels (the ROI); else every other valid pixel is
  /// corrected with the surface model too. The transitional band is always dropped.
  bool roi_only = true;
  /// Surface pixels without a normal (isolated, or at an edge on both axes) are dropped when
  /// true, else corrected with theta = 0.
  bool drop_without_normal = true;
  /// Surface pixels seen at a larger incidence are dropped: their C3 theta term rests on the least
  /// reliable normals [rad]; pi / 2 keeps them all.
  double max_incidence_rad = 1.5707963267948966;
  /// The AB the intensity term reads (the identification's sampling reads it the same way).
  IntensityAbOptions intensity_ab;
};

struct CorrectedFrame {
  Image<float> range_mm;  // corrected radial range [mm], 0 = dropped or invalid
  FrameSegmentation segmentation;
  RangeNormals normals;  // of the measured range
  /// The multipath removal's indirect-to-direct ratio |q| per pixel; empty when the model
  /// removes no multipath.
  Image<float> indirect_ratio;
};

/// The range with marker and transitional pixels set to 0: normals of the surface alone (a marker
/// sits a few mm off the skin, inside the depth-edge tolerance).
Image<float> SurfaceRange(const Image<float>& range_mm, const FrameSegmentation& segmentation);

/// Corrects one frame: segmentation, normals on the measured surface range (SurfaceRange), theta,
/// then Eq. (4) d' = (d - C1 - C3 g(theta) - C4 h(AB)) / (1 + C2) on surface pixels (AB:
/// IntensityAbAt) and Eq. (2) d' = d - f_rf(d) on marker pixels. Throws std::invalid_argument on
/// bad options or sizes.
CorrectedFrame CorrectFrame(const AhatFrame& frame, const AhatCamera& camera,
                            const DepthErrorModel& model, const CorrectRangeOptions& options = {});

/// CorrectFrame's range image only.
Image<float> CorrectRangeImage(const AhatFrame& frame, const AhatCamera& camera,
                               const DepthErrorModel& model,
                               const CorrectRangeOptions& options = {});

}  // namespace tofnav
