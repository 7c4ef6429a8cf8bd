// SPDX-License-Identifier: BSD-3-Clause
// The AHAT camera: per-pixel rays from the calibration table, range to point, point to pixel.
#pragma once

#include <Eigen/Core>
#include <optional>

#include "tofnav/core/image.hpp"
#include "tofnav/core/rigid3d.hpp"
#include "tofnav/sensor/ahat_calibration.hpp"

namespace tofnav {

struct AhatCameraOptions {
  /// c: where our pixel centre (integer index) lies in API coordinates (ahat.md section 5.3).
  double pixel_centre_offset_px = 0.5;
  /// Rays farther than this from the principal point are invalid [px]; 0 keeps every entry that
  /// passes the monotone-region test.
  double valid_radius_px = 0.0;
  void Check() const;
};

/// Camera model of the AHAT sensor. No pinhole fits it (~118 degree fisheye with a folded
/// corner region), so rays come from the device's unit-plane table, and projection inverts the
/// table numerically. A point at range d [mm] along pixel (u, v) is d * Ray(u, v).
/// Frame `ahat`: origin at the optical centre, x right, y down, z forward.
class AhatCamera {
 public:
  explicit AhatCamera(const AhatCalibration& calibration, const AhatCameraOptions& options = {});

  int width() const { return rays_.width(); }
  int height() const { return rays_.height(); }
  const Rigid3d& rig_from_ahat() const { return rig_from_ahat_; }

  /// True where the table is valid and monotone (the invertible region).
  bool IsValid(int u, int v) const { return valid_.Contains(u, v) && valid_(u, v) != 0; }
  /// Unit ray of pixel (u, v) (integer centre); zero vector where invalid.
  const Eigen::Vector3f& PixelRay(int u, int v) const { return rays_(u, v); }
  /// Unit ray at a sub-pixel position (bilinear interpolation of the unit-plane table);
  /// nullopt when any of the four surrounding entries is invalid.
  std::optional<Eigen::Vector3d> Ray(const Eigen::Vector2d& pixel) const;
  /// Point in `ahat` [mm] for a range [mm] along pixel (u, v)'s ray (zero where invalid).
  Eigen::Vector3d PointFromRange(int u, int v, double range_mm) const;
  /// Sub-pixel position whose ray passes through `point_in_ahat`; nullopt outside the
  /// invertible region. Accurate to 0.01 px against Ray().
  std::optional<Eigen::Vector2d> Project(const Eigen::Vector3d& point_in_ahat) const;

 private:
  AhatCameraOptions options_;
  double table_shift_px_ = 0.0;        // c - s: table position of our pixel centre
  Image<Eigen::Vector2f> unit_plane_;  // (x, y) at our pixel centres' table positions
  Image<std::uint8_t> valid_;
  Image<Eigen::Vector3f> rays_;
  Rigid3d rig_from_ahat_;
  // Coarse inverse table on the unit plane; see ahat_camera.cpp.
  Image<Eigen::Vector2f> inverse_;
  Eigen::Vector2d inverse_min_ = Eigen::Vector2d::Zero();
  double inverse_step_ = 1.0;
};

}  // namespace tofnav
