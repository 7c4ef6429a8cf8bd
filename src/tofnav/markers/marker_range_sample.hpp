// SPDX-License-Identifier: BSD-3-Clause
// One observation of the retro-reflector range error, the data of Eq. (1).
#pragma once

namespace tofnav {

/// delta = d_measured - d_true at the measured surface range d (docs/tof_physics.md 5.3). Produced
/// by MeasureMarkerRangeErrors (tracking/), consumed by FitMarkerRangeModel (correction/).
struct MarkerRangeSample {
  double range_mm = 0.0;  // measured surface range d
  double error_mm = 0.0;  // delta
  double weight = 1.0;    // inverse variance, relative
  /// The light's entrance angle on flat tape (the angle between the ray and the tape's normal)
  /// [rad], when known; 0 for spheres (their seen cap faces the camera) and unknown tilts.
  double entrance_rad = 0.0;
};

}  // namespace tofnav
