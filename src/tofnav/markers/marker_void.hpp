// SPDX-License-Identifier: BSD-3-Clause
// What one frame's images show where a pose puts a marker that no blob matched: a marker floating
// in front of a far surface, dark, with nothing in front of it, is not there (docs/tracking.md 6).
#pragma once

#include <Eigen/Core>

#include "tofnav/markers/marker_detection.hpp"
#include "tofnav/sensor/ahat_camera.hpp"
#include "tofnav/sensor/ahat_frame.hpp"

namespace tofnav {

struct MarkerVoidOptions {
  /// AB counts: a pixel this bright may be the marker (a blob the detector dropped); one such
  /// pixel in the marker's disc and the place is not void. The detector's base threshold.
  double ab_threshold = kMarkerAbThreshold;
  /// The surface seen through the marker's disc must lie at least this far behind the marker's
  /// centre [mm]. A marker covered where it sits (a drop, tape, its own plate seen past a dark
  /// disc) reads 1-14 mm behind on the demo's sessions; a wrong three-marker pose of a plate puts
  /// its fourth marker in the air, 95-220 mm in front of the background.
  double behind_margin_mm = 30.0;
  /// Valid ranges needed in the disc (fraction of its pixels): fewer and the images cannot tell.
  double min_valid_fraction = 0.5;
  /// Disc pixels in front of the marker (range < centre - in_front_margin_mm) that make it
  /// hidden rather than void: an occluder as thin as a finger over part of the disc.
  double in_front_margin_mm = 5.0;
  double max_in_front_fraction = 0.1;
  double pad_px = 1.0;  // added to the marker's radius in pixels
  void Check() const;   // throws PreconditionError (std::invalid_argument) naming the bad field
};

/// One frame's range and AB images with the camera that saw them, asked about places where a
/// pose puts an unmatched marker. Holds references: the frame and camera must outlive it.
class MarkerVoidTest {
 public:
  MarkerVoidTest(const AhatFrame& frame, const AhatCamera& camera,
                 const MarkerVoidOptions& options = {});
  /// The defaults, with the brightness threshold the detector used on this frame
  /// (MarkerDetectionResult::ab_threshold; 0 keeps the default).
  MarkerVoidTest(const AhatFrame& frame, const AhatCamera& camera, double detector_ab_threshold);

  /// True when the images show no marker at `centre_in_ahat` [mm] and nothing that could hide
  /// one: the centre projects into the image, no pixel of the marker's disc (radius
  /// marker_diameter_mm / 2, plus pad_px) is as bright as a marker, most of the disc has a valid
  /// range, almost none of it lies in front of the centre, and its median range lies
  /// behind_margin_mm or more behind the centre. False whenever the images cannot tell.
  bool IsVoid(const Eigen::Vector3d& centre_in_ahat, double marker_diameter_mm) const;

 private:
  const AhatFrame& frame_;
  const AhatCamera& camera_;
  MarkerVoidOptions options_;
};

}  // namespace tofnav
