// SPDX-License-Identifier: BSD-3-Clause
// Test-only scenes for fusion: analytic spheres seen by a synthetic AHAT camera, with truth.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <random>
#include <utility>
#include <vector>

#include "tofnav/core/image.hpp"
#include "tofnav/core/rigid3d.hpp"
#include "tofnav/core/statistics.hpp"
#include "tofnav/core/triangle_mesh.hpp"
#include "tofnav/sensor/ahat_calibration.hpp"
#include "tofnav/sensor/ahat_camera.hpp"

namespace tofnav {

/// An equidistant fisheye (r = f theta) of `size` x `size` px with the AHAT's field of view
/// (f = 254 px at 512 px), for tests that must run fast unoptimised. Table written with s = 0.5.
inline AhatCalibration SmallFisheyeCalibration(int size) {
  AhatCalibration calibration;
  calibration.sample_offset_px = 0.5;
  calibration.uv2xy = Image<Eigen::Vector2f>(size, size);
  const double focal_px = 254.0 * size / 512.0;
  const double centre_px = 0.5 * (size - 1) - 0.3;  // off the pixel grid on purpose
  const double max_theta = 1.0;                     // rad; beyond: invalid, like the real corners
  for (int j = 0; j < size; ++j) {
    for (int i = 0; i < size; ++i) {
      const Eigen::Vector2d d(i - centre_px, j - centre_px + 0.2);
      const double r = d.norm();
      const double theta = r / focal_px;
      const double nan = std::numeric_limits<double>::quiet_NaN();
      const Eigen::Vector2d xy = theta > max_theta ? Eigen::Vector2d(nan, nan)
                                 : r < 1e-12       ? Eigen::Vector2d::Zero()
                                                   : Eigen::Vector2d(std::tan(theta) * d / r);
      calibration.uv2xy(i, j) = xy.cast<float>();
    }
  }
  return calibration;
}

/// Camera pose in `tool` for a camera at `eye` looking at `target` (ahat: x right, y down,
/// z forward).
inline Rigid3d LookAt(const Eigen::Vector3d& eye, const Eigen::Vector3d& target) {
  const Eigen::Vector3d z = (target - eye).normalized();
  const Eigen::Vector3d helper =
      std::abs(z.y()) < 0.9 ? Eigen::Vector3d::UnitY() : Eigen::Vector3d::UnitX();
  const Eigen::Vector3d x = helper.cross(z).normalized();
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Matrix3d rotation;
  rotation << x, y, z;
  return {Eigen::Quaterniond(rotation), eye};
}

/// `count` camera poses at `distance_mm` from `centre`, spread over the sphere of directions
/// (Fibonacci lattice), each looking at the centre.
inline std::vector<Rigid3d> OrbitPoses(const Eigen::Vector3d& centre, double distance_mm,
                                       int count) {
  std::vector<Rigid3d> poses;
  const double golden = std::numbers::pi * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < count; ++i) {
    const double z = 1.0 - 2.0 * (i + 0.5) / count;
    const double r = std::sqrt(1.0 - z * z);
    const Eigen::Vector3d direction(r * std::cos(golden * i), r * std::sin(golden * i), z);
    poses.push_back(LookAt(centre + distance_mm * direction, centre));
  }
  return poses;
}

/// Range [mm] along every valid pixel ray to a sphere (0 where the ray misses), plus Gaussian
/// noise of `sigma_mm` when `rng` is given.
inline Image<float> RenderSphere(const AhatCamera& camera, const Rigid3d& tool_from_ahat,
                                 const Eigen::Vector3d& centre_in_tool, double radius_mm,
                                 double sigma_mm = 0.0, std::mt19937_64* rng = nullptr) {
  const Eigen::Vector3d c = tool_from_ahat.Inverse() * centre_in_tool;
  const double c2 = c.squaredNorm() - radius_mm * radius_mm;
  std::normal_distribution<double> noise(0.0, sigma_mm);
  Image<float> range(camera.width(), camera.height(), 0.0f);
  for (int v = 0; v < camera.height(); ++v) {
    for (int u = 0; u < camera.width(); ++u) {
      const Eigen::Vector3f& ray = camera.PixelRay(u, v);  // zero where invalid
      const double b = ray.x() * c.x() + ray.y() * c.y() + ray.z() * c.z();
      const double discriminant = b * b - c2;
      if (!camera.IsValid(u, v) || discriminant < 0.0) continue;
      double d = b - std::sqrt(discriminant);
      if (rng != nullptr) d += noise(*rng);
      range(u, v) = static_cast<float>(d);
    }
  }
  return range;
}

/// An ellipsoid "head" in `tool`: semi-axes along the columns of tool_from_head's rotation.
struct EllipsoidHead {
  Eigen::Vector3d centre_in_tool = Eigen::Vector3d(10.3, -5.6, 20.2);
  Eigen::Matrix3d rotation = Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized())
                                 .toRotationMatrix();  // tool from head axes
  Eigen::Vector3d semi_axes_mm = Eigen::Vector3d(75.0, 95.0, 110.0);

  /// Range along every valid pixel ray to the ellipsoid (0 where it misses), plus Gaussian noise
  /// of sigma_mm drawn from `rng`.
  Image<float> Render(const AhatCamera& camera, const Rigid3d& tool_from_ahat, double sigma_mm,
                      std::mt19937_64& rng) const {
    // In scaled head coordinates the ellipsoid is the unit sphere: solve |o + t d| = 1.
    const Eigen::Matrix3d to_unit = semi_axes_mm.cwiseInverse().asDiagonal() *
                                    rotation.transpose() * tool_from_ahat.RotationMatrix();
    const Eigen::Vector3d o = semi_axes_mm.cwiseInverse().asDiagonal() * rotation.transpose() *
                              (tool_from_ahat.translation - centre_in_tool);
    std::normal_distribution<double> noise(0.0, sigma_mm);
    Image<float> range(camera.width(), camera.height(), 0.0f);
    for (int v = 0; v < camera.height(); ++v) {
      for (int u = 0; u < camera.width(); ++u) {
        if (!camera.IsValid(u, v)) continue;
        const Eigen::Vector3d d = to_unit * camera.PixelRay(u, v).cast<double>();
        const double a = d.squaredNorm(), b = o.dot(d), c = o.squaredNorm() - 1.0;
        const double discriminant = b * b - a * c;
        if (discriminant < 0.0) continue;
        const double t = (-b - std::sqrt(discriminant)) / a;
        if (t > 0.0) range(u, v) = static_cast<float>(t + (sigma_mm > 0.0 ? noise(rng) : 0.0));
      }
    }
    return range;
  }

  /// Signed distance of a point near the surface [mm], to first order: F / |grad F| with
  /// F = |p / semi_axes|^2 - 1 in head axes (exact to O(d^2 / radius of curvature)).
  double DistanceMm(const Eigen::Vector3d& point_in_tool) const {
    const Eigen::Vector3d q = rotation.transpose() * (point_in_tool - centre_in_tool);
    const Eigen::Vector3d scaled = q.cwiseQuotient(semi_axes_mm);
    const Eigen::Vector3d gradient = 2.0 * scaled.cwiseQuotient(semi_axes_mm);
    return (scaled.squaredNorm() - 1.0) / gradient.norm();
  }
};

/// Camera poses at 300 .. 500 mm from `target`, looking at it from directions within
/// `max_angle_rad` of `forward` (a head-worn session sees the face side), seeded.
inline std::vector<Rigid3d> FrontPoses(const Eigen::Vector3d& target,
                                       const Eigen::Vector3d& forward, double max_angle_rad,
                                       int count, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const Eigen::Vector3d f = forward.normalized();
  const Eigen::Vector3d side = f.unitOrthogonal(), up = f.cross(side);
  std::vector<Rigid3d> poses;
  for (int i = 0; i < count; ++i) {
    // Uniform over the spherical cap, distance uniform in [300, 500] mm.
    const double cos_angle = 1.0 - unit(rng) * (1.0 - std::cos(max_angle_rad));
    const double azimuth = 2.0 * std::numbers::pi * unit(rng);
    const double sin_angle = std::sqrt(1.0 - cos_angle * cos_angle);
    const Eigen::Vector3d direction =
        cos_angle * f + sin_angle * (std::cos(azimuth) * side + std::sin(azimuth) * up);
    poses.push_back(LookAt(target + (300.0 + 200.0 * unit(rng)) * direction, target));
  }
  return poses;
}

/// Median of |error| [mm] (docs/statistics.md); infinity when empty.
inline double MedianAbs(std::vector<double> errors) {
  if (errors.empty()) return std::numeric_limits<double>::infinity();
  for (double& e : errors) e = std::abs(e);
  return Median(errors);
}

/// Median of | |v - centre| - radius | over the mesh vertices [mm].
inline double MedianSphereErrorMm(const TriangleMesh& mesh, const Eigen::Vector3d& centre,
                                  double radius_mm) {
  std::vector<double> errors;
  for (const Eigen::Vector3d& v : mesh.vertices) errors.push_back((v - centre).norm() - radius_mm);
  return MedianAbs(std::move(errors));
}

}  // namespace tofnav
