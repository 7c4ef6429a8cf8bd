// SPDX-License-Identifier: BSD-3-Clause
// Analytic truth for the correction tests: planes in AHAT frames, sphere heads with stickers.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>

#include "tofnav/core/image.hpp"
#include "tofnav/core/point_cloud.hpp"
#include "tofnav/correction/identification_frame.hpp"
#include "tofnav/sensor/ahat_calibration.hpp"
#include "tofnav/sensor/ahat_camera.hpp"
#include "tofnav/sensor/ahat_frame.hpp"

namespace tofnav::testing {

inline const AhatCamera& CorrectionCamera() {
  static const AhatCamera camera(MakeSyntheticAhatCalibration());
  return camera;
}

/// A plane n . X = offset (unit n pointing away from the camera side, offset > 0).
struct TestPlane {
  Eigen::Vector3d normal;
  double offset_mm = 0.0;
  /// True range along `ray`, 0 when the plane is behind the camera or grazing.
  double Range(const Eigen::Vector3d& ray) const {
    const double c = normal.dot(ray);
    return c > 1e-3 ? offset_mm / c : 0.0;
  }
  double Incidence(const Eigen::Vector3d& ray) const {
    return std::acos(std::abs(normal.dot(ray)));
  }
};

/// A plane through `point` facing the camera, turned by `angle_rad` about the y axis.
inline TestPlane TiltedPlane(double distance_mm, double angle_rad) {
  const Eigen::Vector3d n(std::sin(angle_rad), 0.0, std::cos(angle_rad));
  return {n, distance_mm * n.z()};
}

/// Frame of true range `truth(u, v, ray)` [mm] with a measured range `measured(d, ray)` rounded to
/// mm, uniform AB `ab`, inside the pixel window [min_px, max_px]^2; pixels with truth 0 and those
/// outside the window are invalid (a small window keeps unoptimised tests fast).
inline AhatFrame SyntheticFrame(
    const std::function<double(int, int, const Eigen::Vector3d&)>& truth,
    const std::function<double(double, int, int)>& measured, std::uint16_t ab,
    Image<float>* truth_out = nullptr, int min_px = 0, int max_px = 511) {
  const AhatCamera& camera = CorrectionCamera();
  AhatFrame frame;
  frame.range_mm = Image<std::uint16_t>(camera.width(), camera.height());
  frame.ab = Image<std::uint16_t>(camera.width(), camera.height(), ab);
  if (truth_out) *truth_out = Image<float>(camera.width(), camera.height());
  for (int v = std::max(min_px, 0); v <= std::min(max_px, camera.height() - 1); ++v) {
    for (int u = std::max(min_px, 0); u <= std::min(max_px, camera.width() - 1); ++u) {
      if (!camera.IsValid(u, v)) continue;
      const Eigen::Vector3d ray = camera.PixelRay(u, v).cast<double>();
      const double d = truth(u, v, ray);
      if (d <= 0.0) continue;
      if (truth_out) (*truth_out)(u, v) = static_cast<float>(d);
      frame.range_mm(u, v) = static_cast<std::uint16_t>(std::lround(measured(d, u, v)));
    }
  }
  return frame;
}

inline constexpr double kHeadRadiusMm = 90.0;
inline constexpr double kPi = 3.14159265358979323846;

inline DepthErrorModel TrueModel() {
  DepthErrorModel m;
  m.c1_mm = 2.8;
  m.c2 = 0.010;
  m.c3_mm = 4.0;
  return m;
}

// A surface sample of the sphere at `point` (camera at the origin), measured with `model`. Its AB
// is 130 everywhere, or with `lambertian_ab` that of an albedo-0.6 surface under an illuminator of
// 65 counts m^2 (docs/tof_physics.md): 39 cos(theta) / d^2, d in m.
inline SurfaceSample SphereSample(const Eigen::Vector3d& point, const Eigen::Vector3d& centre,
                                  const DepthErrorModel& model, bool lambertian_ab = false) {
  const double d = point.norm();
  const Eigen::Vector3d ray = point / d;
  const double theta = std::acos(std::abs(ray.dot((point - centre).normalized())));
  const double ab = lambertian_ab ? 39.0 * std::cos(theta) / (d * d * 1e-6) : 130.0;
  return {ray.cast<float>(), static_cast<float>(d + model.BiasMm(d, theta, ab)),
          static_cast<float>(theta), static_cast<float>(ab)};
}

// Point of the sphere at polar angle `a` from the direction `axis` towards the camera, turned by
// `phi` about it.
inline Eigen::Vector3d SpherePoint(const Eigen::Vector3d& centre, const Eigen::Vector3d& axis,
                                   double a, double phi) {
  const Eigen::Vector3d e1 = axis.unitOrthogonal(), e2 = axis.cross(e1);
  return centre + kHeadRadiusMm * (std::cos(a) * axis +
                                   std::sin(a) * (std::cos(phi) * e1 + std::sin(phi) * e2));
}

// One frame: a sphere head at `centre` (camera at the origin) with three markers (curved 5 mm
// stickers, exact on the sphere and unbiased) at various angles from the view axis.
inline IdentificationFrame SphereFrame(int index, const Eigen::Vector3d& centre,
                                       const DepthErrorModel& model, int ring_points = 8,
                                       double ring_step_mm = 4.3, bool lambertian_ab = false) {
  IdentificationFrame frame;
  frame.index = index;
  const Eigen::Vector3d toward = -centre.normalized();
  const double marker_angles[] = {0.15, 0.5, 0.85};
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector3d axis =
        Eigen::AngleAxisd(marker_angles[k], Eigen::Vector3d::UnitY()) * toward;
    MarkerPatch patch;
    patch.scale_mm = 22.0;
    for (double r = 0.0; r <= 5.0; r += 2.5) {
      for (int i = 0; i < (r == 0.0 ? 1 : 8); ++i) {
        patch.marker_points.push_back(
            SpherePoint(centre, axis.normalized(), r / kHeadRadiusMm, i * kPi / 4));
      }
    }
    for (double r = 9.0; r <= 22.0; r += ring_step_mm) {
      for (int i = 0; i < ring_points; ++i) {
        patch.neighbours.push_back(
            SphereSample(SpherePoint(centre, axis.normalized(), r / kHeadRadiusMm,
                                     (i + 0.3 * r) * 2 * kPi / ring_points),
                         centre, model, lambertian_ab));
      }
    }
    // Local frame as PrepareIdentificationFrame sets it (origin, z towards the camera).
    patch.origin_in_ahat = centre + kHeadRadiusMm * axis.normalized();
    const Eigen::Vector3d z = axis.normalized(), x = z.unitOrthogonal();
    patch.local_from_ahat.row(0) = x.transpose();
    patch.local_from_ahat.row(1) = z.cross(x).transpose();
    patch.local_from_ahat.row(2) = z.transpose();
    frame.marker_points.insert(frame.marker_points.end(), patch.marker_points.begin(),
                               patch.marker_points.end());
    frame.markers.push_back(std::move(patch));
  }
  for (int i = 0; i < 60; ++i) {  // head samples for the ICP: a cap facing the camera
    frame.head.push_back(
        SphereSample(SpherePoint(centre, toward, 0.9 * std::sqrt((i % 12) / 12.0), i * 0.7), centre,
                     model, lambertian_ab));
  }
  return frame;
}

inline std::vector<IdentificationFrame> SphereFrames(const DepthErrorModel& model,
                                                     bool lambertian_ab = false) {
  std::vector<IdentificationFrame> frames;
  const double ranges[] = {380.0, 520.0, 660.0, 800.0};
  for (int i = 0; i < 4; ++i) {
    const Eigen::Vector3d centre = Eigen::AngleAxisd(0.2 * i - 0.3, Eigen::Vector3d::UnitX()) *
                                   Eigen::Vector3d(20.0 * i - 30.0, 0.0, ranges[i]);
    frames.push_back(SphereFrame(i, centre, model, 8, 4.3, lambertian_ab));
  }
  return frames;
}

/// The sphere head as a skin cloud in its own frame (centre at the origin), 3 deg sampling.
inline PointCloud SphereSkin() {
  PointCloud skin;
  for (int i = 0; i < 60; ++i) {
    for (int j = 0; j < 120; ++j) {
      const double a = (i + 0.5) * kPi / 60, b = j * kPi / 60;
      const Eigen::Vector3d n(std::sin(a) * std::cos(b), std::sin(a) * std::sin(b), std::cos(a));
      skin.points.push_back(kHeadRadiusMm * n);
      skin.normals.push_back(n);
    }
  }
  return skin;
}

/// image_from_ahat of a sphere frame (the sphere centre to the origin), offset by `error_mm`.
inline Rigid3d SphereImageFromAhat(const IdentificationFrame& frame,
                                   const Eigen::Vector3d& error_mm) {
  const MarkerPatch& patch = frame.markers[0];
  const Eigen::Vector3d centre =
      patch.origin_in_ahat - kHeadRadiusMm * patch.local_from_ahat.row(2).transpose();
  return Rigid3d(Eigen::Quaterniond::Identity(), -centre + error_mm);
}

}  // namespace tofnav::testing
