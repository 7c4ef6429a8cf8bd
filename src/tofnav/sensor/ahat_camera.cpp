// SPDX-License-Identifier: BSD-3-Clause
// The AHAT camera: per-pixel rays from the calibration table, range to point, point to pixel.
#include "tofnav/sensor/ahat_camera.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "tofnav/core/require.hpp"

namespace tofnav {
namespace {

constexpr int kMaxInverseNodes = 2048;  // per side; bounds memory for any table
// Inverse-table node spacing, in centre pixels; not a whole number, so that nodes do not line up
// with cell edges along whole rows or columns.
constexpr double kInverseStepPx = 1.93;
// A node this close to a cell (in cell fractions) is claimed by it: float rounding must not let
// a node on a shared edge fall between two cells. The guess only needs to be near.
constexpr double kNodeSlack = 0.01;
constexpr int kInverseDilations = 2;  // nodes just outside the region still give a guess
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

/// The inverse table lives on the equidistant ("angle") plane: unit-plane direction times
/// theta = atan(rho). A fisheye's pixels are nearly uniform there, and it is bounded by pi / 2.
PlanePoint AnglePlaneFromUnitPlane(double x, double y) {
  const double rho = std::sqrt(x * x + y * y);
  const double scale = rho > 1e-12 ? std::atan(rho) / rho : 1.0;
  return {static_cast<float>(scale * x), static_cast<float>(scale * y)};
}

/// Fills NaN nodes from a finite 8-neighbour, so points just outside the scattered region still
/// get a start for Newton (which then decides validity).
Image<PlanePoint> Dilate(const Image<PlanePoint>& nodes) {
  Image<PlanePoint> out = nodes;
  for (int j = 0; j < nodes.height(); ++j) {
    for (int i = 0; i < nodes.width(); ++i) {
      if (nodes(i, j).finite()) continue;
      for (int k = 0; k < 9; ++k) {
        const int ni = i + k % 3 - 1;
        const int nj = j + k / 3 - 1;
        if (nodes.Contains(ni, nj) && nodes(ni, nj).finite()) {
          out(i, j) = nodes(ni, nj);
          break;
        }
      }
    }
  }
  return out;
}

}  // namespace

void AhatCameraOptions::Check() const {
  Require(pixel_centre_offset_px >= 0.0 && pixel_centre_offset_px < 1.0,
          "AhatCameraOptions::pixel_centre_offset_px must be in [0, 1)");
  Require(valid_radius_px >= 0.0, "AhatCameraOptions::valid_radius_px must be >= 0");
}

AhatCamera::AhatCamera(const AhatCalibration& calibration, const AhatCameraOptions& options)
    : options_(options), rig_from_ahat_(calibration.rig_from_ahat) {
  options.Check();
  Require(calibration.uv2xy.width() >= 2 && calibration.uv2xy.height() >= 2,
          "AhatCalibration::uv2xy must hold at least 2 x 2 entries");
  Require(calibration.sample_offset_px >= 0.0 && calibration.sample_offset_px < 1.0,
          "AhatCalibration::sample_offset_px must be in [0, 1)");
  const UnitPlaneTable table = ToUnitPlaneTable(calibration.uv2xy);
  // docs/ahat.md section 5.3: our pixel centre (u, v) is the table position (u + c - s, v + c - s).
  table_shift_px_ = options.pixel_centre_offset_px - calibration.sample_offset_px;
  const std::optional<Eigen::Vector2d> table_principal_point = FindTablePrincipalPoint(table);
  Require(table_principal_point.has_value(),
          "AhatCalibration::uv2xy has no monotone entry around x = y = 0");
  principal_point_px_ = *table_principal_point - Eigen::Vector2d::Constant(table_shift_px_);

  ResampledTable resampled =
      ResampleTable(table, MonotoneTableMask(table, *table_principal_point), table_shift_px_);
  unit_plane_ = std::move(resampled.table);
  valid_ = DropFoldingEntries(unit_plane_, resampled.valid);
  rays_ = Image<Eigen::Vector3f>(table.width(), table.height(), Eigen::Vector3f::Zero());
  const double radius2 = options.valid_radius_px * options.valid_radius_px;
  for (int v = 0; v < height(); ++v) {
    for (int u = 0; u < width(); ++u) {
      const double du = u - principal_point_px_.x();
      const double dv = v - principal_point_px_.y();
      if (options.valid_radius_px > 0.0 && du * du + dv * dv > radius2) valid_(u, v) = 0;
      if (valid_(u, v) == 0) continue;
      const PlanePoint& xy = unit_plane_(u, v);
      const float norm = std::sqrt(xy.x * xy.x + xy.y * xy.y + 1.0f);
      rays_(u, v) = Eigen::Vector3f(xy.x / norm, xy.y / norm, 1.0f / norm);
    }
  }
  cell_valid_ = CellMask(valid_);
  BuildInverseTable();
}

void AhatCamera::BuildInverseTable() {
  Image<PlanePoint> angle(width(), height(), PlanePoint{kNaN, kNaN});
  double low_x = std::numeric_limits<double>::infinity();
  double low_y = low_x;
  double high_x = -low_x;
  double high_y = -low_x;
  for (int v = 0; v < height(); ++v) {
    for (int u = 0; u < width(); ++u) {
      if (valid_(u, v) == 0) continue;
      const PlanePoint point = AnglePlaneFromUnitPlane(unit_plane_(u, v).x, unit_plane_(u, v).y);
      angle(u, v) = point;
      low_x = std::min(low_x, double{point.x});
      low_y = std::min(low_y, double{point.y});
      high_x = std::max(high_x, double{point.x});
      high_y = std::max(high_y, double{point.y});
    }
  }
  if (!(low_x <= high_x)) return;  // nothing valid: Project always fails
  // Node spacing: a few pixels at the principal point (about 1 / f on the angle plane).
  const int pu = std::clamp(static_cast<int>(principal_point_px_.x()), 0, width() - 2);
  const int pv = std::clamp(static_cast<int>(principal_point_px_.y()), 0, height() - 2);
  const PlanePoint& p00 = unit_plane_(pu, pv);
  const PlanePoint& p10 = unit_plane_(pu + 1, pv);
  const PlanePoint& p01 = unit_plane_(pu, pv + 1);
  const double centre_px = std::sqrt(
      std::abs(double{p10.x - p00.x} * (p01.y - p00.y) - double{p10.y - p00.y} * (p01.x - p00.x)));
  const double extent = std::max(high_x - low_x, high_y - low_y);
  inverse_step_ = std::isfinite(centre_px) ? kInverseStepPx * centre_px : 0.0;
  inverse_step_ = std::max(inverse_step_, extent / (kMaxInverseNodes - 3));
  if (!(inverse_step_ > 0.0)) inverse_step_ = 1.0;
  inverse_min_ = Eigen::Vector2d(low_x - inverse_step_, low_y - inverse_step_);
  const double min_x = inverse_min_.x();
  const double min_y = inverse_min_.y();
  inverse_ = Image<PlanePoint>(static_cast<int>(std::ceil((high_x - low_x) / inverse_step_)) + 3,
                               static_cast<int>(std::ceil((high_y - low_y) / inverse_step_)) + 3,
                               PlanePoint{kNaN, kNaN});

  // Scatter: each valid cell inverts the nodes inside its angle-plane bounding box.
  for (int v = 0; v + 1 < height(); ++v) {
    for (int u = 0; u + 1 < width(); ++u) {
      if (cell_valid_(u, v) == 0) continue;
      const PlanePoint& a = angle(u, v);
      const PlanePoint& b = angle(u + 1, v);
      const PlanePoint& c = angle(u, v + 1);
      const PlanePoint& d = angle(u + 1, v + 1);
      const double pad = kNodeSlack * inverse_step_;
      const double cell_low_x = std::min({a.x, b.x, c.x, d.x}) - pad;
      const double cell_high_x = std::max({a.x, b.x, c.x, d.x}) + pad;
      const double cell_low_y = std::min({a.y, b.y, c.y, d.y}) - pad;
      const double cell_high_y = std::max({a.y, b.y, c.y, d.y}) + pad;
      const int first_i = static_cast<int>(std::ceil((cell_low_x - min_x) / inverse_step_));
      const int last_i = static_cast<int>(std::floor((cell_high_x - min_x) / inverse_step_));
      const int first_j = static_cast<int>(std::ceil((cell_low_y - min_y) / inverse_step_));
      const int last_j = static_cast<int>(std::floor((cell_high_y - min_y) / inverse_step_));
      for (int j = first_j; j <= last_j; ++j) {
        for (int i = first_i; i <= last_i; ++i) {
          const double node_x = min_x + inverse_step_ * i;
          const double node_y = min_y + inverse_step_ * j;
          const double theta = std::sqrt(node_x * node_x + node_y * node_y);
          if (!(theta < std::numbers::pi / 2.0)) continue;
          const double scale = theta > 1e-12 ? std::tan(theta) / theta : 1.0;
          const std::optional<Eigen::Vector2d> ab =
              SolveInCell(unit_plane_, u, v, Eigen::Vector2d(scale * node_x, scale * node_y));
          if (ab && ab->x() >= -kNodeSlack && ab->x() <= 1.0 + kNodeSlack &&
              ab->y() >= -kNodeSlack && ab->y() <= 1.0 + kNodeSlack) {
            inverse_(i, j) = {static_cast<float>(u + ab->x()), static_cast<float>(v + ab->y())};
          }
        }
      }
    }
  }
  for (int pass = 0; pass < kInverseDilations; ++pass) inverse_ = Dilate(inverse_);
}

std::optional<Eigen::Vector2d> AhatCamera::InitialGuess(const Eigen::Vector2d& xy) const {
  const PlanePoint angle = AnglePlaneFromUnitPlane(xy.x(), xy.y());
  const double gx = (angle.x - inverse_min_.x()) / inverse_step_;
  const double gy = (angle.y - inverse_min_.y()) / inverse_step_;
  if (!(gx >= 0.0 && gy >= 0.0 && gx < inverse_.width() - 1 && gy < inverse_.height() - 1)) {
    return std::nullopt;
  }
  const int i = static_cast<int>(gx);
  const int j = static_cast<int>(gy);
  const double a = gx - i;
  const double b = gy - j;
  const PlanePoint& q00 = inverse_(i, j);
  const PlanePoint& q10 = inverse_(i + 1, j);
  const PlanePoint& q01 = inverse_(i, j + 1);
  const PlanePoint& q11 = inverse_(i + 1, j + 1);
  if (q00.finite() && q10.finite() && q01.finite() && q11.finite()) {
    return Eigen::Vector2d(
        (1.0 - b) * ((1.0 - a) * q00.x + a * q10.x) + b * ((1.0 - a) * q01.x + a * q11.x),
        (1.0 - b) * ((1.0 - a) * q00.y + a * q10.y) + b * ((1.0 - a) * q01.y + a * q11.y));
  }
  for (const PlanePoint* q : {&q00, &q10, &q01, &q11}) {
    if (q->finite()) return Eigen::Vector2d(q->x, q->y);
  }
  return std::nullopt;
}

std::optional<Eigen::Vector3d> AhatCamera::Ray(const Eigen::Vector2d& pixel) const {
  const double u_floor = std::floor(pixel.x());
  const double v_floor = std::floor(pixel.y());
  if (!(u_floor >= 0.0 && v_floor >= 0.0 && u_floor < width() && v_floor < height())) {
    return std::nullopt;  // also rejects NaN
  }
  const int u0 = static_cast<int>(u_floor);
  const int v0 = static_cast<int>(v_floor);
  const double a = pixel.x() - u_floor;
  const double b = pixel.y() - v_floor;
  const int u1 = a > 0.0 ? u0 + 1 : u0;  // zero-weight neighbours are not needed
  const int v1 = b > 0.0 ? v0 + 1 : v0;
  if (!IsValid(u0, v0) || !IsValid(u1, v0) || !IsValid(u0, v1) || !IsValid(u1, v1)) {
    return std::nullopt;
  }
  const PlanePoint& q00 = unit_plane_(u0, v0);
  const PlanePoint& q10 = unit_plane_(u1, v0);
  const PlanePoint& q01 = unit_plane_(u0, v1);
  const PlanePoint& q11 = unit_plane_(u1, v1);
  const double x =
      (1.0 - b) * ((1.0 - a) * q00.x + a * q10.x) + b * ((1.0 - a) * q01.x + a * q11.x);
  const double y =
      (1.0 - b) * ((1.0 - a) * q00.y + a * q10.y) + b * ((1.0 - a) * q01.y + a * q11.y);
  const double norm = std::sqrt(x * x + y * y + 1.0);
  return Eigen::Vector3d(x / norm, y / norm, 1.0 / norm);
}

Eigen::Vector3d AhatCamera::PointFromRange(int u, int v, double range_mm) const {
  const Eigen::Vector3f& ray = rays_.At(u, v);
  return {range_mm * ray.x(), range_mm * ray.y(), range_mm * ray.z()};
}

std::optional<Eigen::Vector2d> AhatCamera::Project(const Eigen::Vector3d& point_in_ahat) const {
  const double z = point_in_ahat.z();
  if (!(z > 0.0) || !std::isfinite(z) || !std::isfinite(point_in_ahat.x()) ||
      !std::isfinite(point_in_ahat.y())) {
    return std::nullopt;
  }
  const Eigen::Vector2d xy(point_in_ahat.x() / z, point_in_ahat.y() / z);
  const std::optional<Eigen::Vector2d> guess = InitialGuess(xy);
  if (!guess) return std::nullopt;
  return InvertBilinear(unit_plane_, cell_valid_, xy, *guess);
}

}  // namespace tofnav
