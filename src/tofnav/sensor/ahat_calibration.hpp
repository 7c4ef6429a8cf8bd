// SPDX-License-Identifier: BSD-3-Clause
// The AHAT calibration as the device reports it (hl2ss folder or Mode-2 blob, StreamRecorder LUT),
// and a synthetic one with known truth for tests and the simulator.
#pragma once

#include <Eigen/Core>

#include "tofnav/core/image.hpp"
#include "tofnav/core/rigid3d.hpp"

namespace tofnav {

/// Our convention for the API coordinate of a pixel centre: API = array index + 0.5 (the c of
/// docs/ahat.md 5.3). The synthetic generator writes tables with it; AhatCameraOptions defaults
/// to it.
constexpr double kApiPixelCentreOffsetPx = 0.5;

/// Device calibration contents, in our units and conventions (io/ converts on read).
struct AhatCalibration {
  /// Unit-plane (x, y) (z = 1) of the API point (i + s, j + s) for array index (i, j) = (column,
  /// row); NaN where the source marks the entry invalid (StreamRecorder z == 0).
  Image<Eigen::Vector2f> uv2xy;
  /// s: where the table was sampled relative to the array index: 0.5 for hl2ss <= v1.0.35 and
  /// StreamRecorder, 0 for hl2ss >= v1.0.36 (docs/ahat.md section 5.3).
  double sample_offset_px = 0.5;
  /// Inverse of the stored rig -> camera extrinsics, translation in mm.
  Rigid3d rig_from_ahat;
  /// hl2ss virtual pinhole: raw-image API coordinate seen by each pinhole pixel; empty if absent.
  Image<Eigen::Vector2f> undistort_map;
  Eigen::Vector4d pinhole_fx_fy_cx_cy = Eigen::Vector4d::Zero();  // [px]; zero if absent
  double scale = 1000.0;     // depth units per metre, as stored
  double alias_mm = 1055.0;  // phase-wrap distance, as stored
};

/// Parameters of a synthetic AHAT calibration (docs/ahat.md section 11).
struct SyntheticAhatOptions {
  double focal_px = 254.0;  // equidistant r = f * theta
  /// Principal point in array-index coordinates (pixel centres at integers).
  Eigen::Vector2d principal_point_px = {252.4, 252.8};
  double aspect_y = 1.0;  // y focal / x focal
  /// Cubic term of the realistic profile theta(r) = r / f + cubic * r^3 (0 = pure equidistant).
  double cubic_rad_per_px3 = 0.0;
  /// Beyond this radius the table folds back, as real tables do at the corners [px].
  double fold_radius_px = 262.0;
  double sample_offset_px = 0.5;  // s of the written table
  /// Pinhole of the undistort map: 512 x 512, focal length [px] (254 covers about +-45 degrees),
  /// centre (255.5, 255.5) in integer-centred pinhole indices.
  double pinhole_focal_px = 254.0;
  Rigid3d rig_from_ahat;  // identity by default; TypicalRigFromAhat() gives the measured device
  void Check() const;     // throws PreconditionError naming the bad field
};

/// The measured device extrinsics of docs/ahat.md section 10, rounded, as rig_from_ahat [mm].
Rigid3d TypicalRigFromAhat();

/// Builds a 512 x 512 calibration from the model: unit-plane table (entries with theta outside
/// (-pi/2, pi/2) are NaN), undistort map (raw API coordinates, -1 outside the unfolded field), K,
/// extrinsics. Throws PreconditionError on a bad option.
AhatCalibration MakeSyntheticAhatCalibration(const SyntheticAhatOptions& options = {});

}  // namespace tofnav
