// SPDX-License-Identifier: BSD-3-Clause
// Synthetic AHAT calibration (docs/ahat.md 11) and the measured device extrinsics (section 10).
#include "tofnav/sensor/ahat_calibration.hpp"

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>

#include "tofnav/core/require.hpp"
#include "tofnav/core/units.hpp"
#include "tofnav/sensor/ahat_frame.hpp"

namespace tofnav {
namespace {

constexpr double kPinholeCentrePx = 255.5;  // centre of a 512-pixel pinhole, integer-centred

/// Radial profile theta(r) with the fold of docs/ahat.md section 11 beyond fold_radius_px.
class RadialProfile {
 public:
  explicit RadialProfile(const SyntheticAhatOptions& options)
      : focal_px_(options.focal_px),
        cubic_(options.cubic_rad_per_px3),
        fold_radius_px_(options.fold_radius_px),
        fold_theta_rad_(Unfolded(options.fold_radius_px)) {}

  double ThetaRad(double r_px) const {
    if (r_px <= fold_radius_px_) return Unfolded(r_px);
    return fold_theta_rad_ - (r_px - fold_radius_px_) / focal_px_;
  }

  /// Radius on the unfolded branch [0, fold_radius] whose angle is theta; nullopt beyond it.
  std::optional<double> RadiusPx(double theta_rad) const {
    if (theta_rad < 0.0 || theta_rad > fold_theta_rad_) return std::nullopt;
    double r_px = theta_rad * focal_px_;
    if (cubic_ == 0.0) return std::min(r_px, fold_radius_px_);  // equidistant: closed form
    for (int iteration = 0; iteration < 50; ++iteration) {      // Newton on the monotone branch
      const double slope = 1.0 / focal_px_ + 3.0 * cubic_ * r_px * r_px;
      if (!(slope > 0.0)) return std::nullopt;
      const double step = (Unfolded(r_px) - theta_rad) / slope;
      r_px -= step;
      if (std::abs(step) < 1e-12 * (1.0 + r_px)) break;
    }
    if (!(r_px >= 0.0 && r_px <= fold_radius_px_ * (1.0 + 1e-12))) return std::nullopt;
    return r_px;
  }

 private:
  double Unfolded(double r_px) const { return r_px / focal_px_ + cubic_ * r_px * r_px * r_px; }

  double focal_px_;
  double cubic_;
  double fold_radius_px_;
  double fold_theta_rad_;
};

/// Unit-plane (x, y) of the point offset (dx, dy) [px] from the principal point; NaN past 90
/// degrees. Scalar code: this runs for every entry, and tests build tables unoptimised.
Eigen::Vector2f UnitPlaneOf(double dx_px, double dy_px, const RadialProfile& profile,
                            double aspect_y) {
  // The aspect acts before the radial model: (dx, dy / aspect) is the isotropic offset.
  const double iy_px = dy_px / aspect_y;
  const double r_px = std::sqrt(dx_px * dx_px + iy_px * iy_px);
  if (r_px == 0.0) return Eigen::Vector2f::Zero();
  const double theta_rad = profile.ThetaRad(r_px);
  if (!(std::abs(theta_rad) < std::numbers::pi / 2.0)) {
    return Eigen::Vector2f::Constant(std::numeric_limits<float>::quiet_NaN());
  }
  const double scale = std::tan(theta_rad) / r_px;
  return {static_cast<float>(scale * dx_px), static_cast<float>(scale * iy_px)};
}

/// Raw API coordinate seen by pinhole pixel (u, v); (-1, -1) outside the unfolded field.
Eigen::Vector2f UndistortEntry(int u, int v, const SyntheticAhatOptions& options,
                               const RadialProfile& profile) {
  const Eigen::Vector2f outside(-1.0f, -1.0f);
  const double x = (u - kPinholeCentrePx) / options.pinhole_focal_px;
  const double y = (v - kPinholeCentrePx) / options.pinhole_focal_px;
  const double rho = std::sqrt(x * x + y * y);
  double scale = 0.0;  // isotropic offset [px] per unit-plane unit
  if (rho > 0.0) {
    const std::optional<double> r_px = profile.RadiusPx(std::atan(rho));
    if (!r_px) return outside;
    scale = *r_px / rho;
  }
  const double api_x = options.principal_point_px.x() + scale * x + kApiPixelCentreOffsetPx;
  const double api_y =
      options.principal_point_px.y() + scale * y * options.aspect_y + kApiPixelCentreOffsetPx;
  if (!(api_x >= 0.0 && api_y >= 0.0 && api_x <= kAhatWidth && api_y <= kAhatHeight)) {
    return outside;
  }
  return {static_cast<float>(api_x), static_cast<float>(api_y)};
}

}  // namespace

void SyntheticAhatOptions::Check() const {
  Require(std::isfinite(focal_px) && focal_px > 0.0, "SyntheticAhatOptions::focal_px must be > 0");
  Require(principal_point_px.allFinite(),
          "SyntheticAhatOptions::principal_point_px must be finite");
  Require(std::isfinite(aspect_y) && aspect_y > 0.0, "SyntheticAhatOptions::aspect_y must be > 0");
  Require(std::isfinite(cubic_rad_per_px3),
          "SyntheticAhatOptions::cubic_rad_per_px3 must be finite");
  Require(std::isfinite(fold_radius_px) && fold_radius_px > 0.0,
          "SyntheticAhatOptions::fold_radius_px must be > 0");
  Require(sample_offset_px >= 0.0 && sample_offset_px < 1.0,
          "SyntheticAhatOptions::sample_offset_px must be in [0, 1)");
  Require(std::isfinite(pinhole_focal_px) && pinhole_focal_px > 0.0,
          "SyntheticAhatOptions::pinhole_focal_px must be > 0");
}

Rigid3d TypicalRigFromAhat() {
  // docs/ahat.md section 10: E (rig -> camera, row vectors: p_cam = p_rig * R + t), rounded.
  Eigen::Matrix3d rotation_rows;
  rotation_rows << 0.0214, 0.9580, 0.2860,  //
      -0.9995, 0.0270, -0.0156,             //
      -0.0227, -0.2856, 0.9581;
  const Eigen::Vector3d translation_m(-0.0594, -0.0153, -0.0183);
  // Column vectors: ahat_from_rig = (R^T, t), so rig_from_ahat = (R, -R t). The rounded R is
  // projected onto SO(3) first.
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(rotation_rows,
                                              Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Matrix3d rig_from_ahat_rotation = svd.matrixU() * svd.matrixV().transpose();
  return {Eigen::Quaterniond(rig_from_ahat_rotation),
          -(rig_from_ahat_rotation * translation_m) * kMmPerMetre};
}

AhatCalibration MakeSyntheticAhatCalibration(const SyntheticAhatOptions& options) {
  options.Check();
  const RadialProfile profile(options);
  AhatCalibration calibration;
  calibration.uv2xy = Image<Eigen::Vector2f>(kAhatWidth, kAhatHeight, Eigen::Vector2f::Zero());
  calibration.undistort_map =
      Image<Eigen::Vector2f>(kAhatWidth, kAhatHeight, Eigen::Vector2f::Zero());
  // Entry (i, j) is the API point (i + s, j + s), i.e. index coordinate (i + s - c) (section 11).
  const double index_shift_px = options.sample_offset_px - kApiPixelCentreOffsetPx;
  const double cx = options.principal_point_px.x();
  const double cy = options.principal_point_px.y();
  for (int j = 0; j < kAhatHeight; ++j) {
    for (int i = 0; i < kAhatWidth; ++i) {
      calibration.uv2xy(i, j) =
          UnitPlaneOf(i + index_shift_px - cx, j + index_shift_px - cy, profile, options.aspect_y);
      calibration.undistort_map(i, j) = UndistortEntry(i, j, options, profile);
    }
  }
  calibration.sample_offset_px = options.sample_offset_px;
  calibration.rig_from_ahat = options.rig_from_ahat;
  calibration.pinhole_fx_fy_cx_cy = {options.pinhole_focal_px, options.pinhole_focal_px,
                                     kPinholeCentrePx, kPinholeCentrePx};
  calibration.scale = 1000.0;
  calibration.alias_mm = kAhatAliasMm;
  return calibration;
}

}  // namespace tofnav
