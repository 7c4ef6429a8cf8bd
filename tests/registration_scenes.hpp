// SPDX-License-Identifier: BSD-3-Clause
// Test scenes for registration/: the simulator's head phantom, partial face reconstructions,
// random poses (header-only; registration tests and bench/registration_bench.cpp).
#pragma once

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "tofnav/core/point_cloud.hpp"
#include "tofnav/core/rigid3d.hpp"
#include "tofnav/core/triangle_mesh.hpp"
#include "tofnav/registration/register_surface.hpp"
#include "tofnav/sim/head_phantom.hpp"

namespace tofnav::test {

/// The phantom skin in its own frame (used as `image`): +x left, +y anterior, +z superior.
/// 96 segments: vertices about 6 mm apart, small enough for unoptimised tests.
inline TriangleMesh PhantomSkin(int segments = 96) {
  sim::HeadPhantomOptions options;
  options.segments = segments;
  return sim::HeadPhantomMesh(options);
}

/// Deep targets of the phantom (image frame) [mm]: about 60-70 mm behind the forehead skin, where
/// ventricle catheters aim (foramina of Monro, frontal horns).
inline std::vector<Eigen::Vector3d> DeepTargets() {
  return {{0.0, 25.0, 20.0}, {-15.0, 20.0, 30.0}, {15.0, 20.0, 30.0}, {0.0, -10.0, 25.0}};
}

/// True where a head-worn camera in front of the face sees the skin: face and forehead.
inline bool IsFrontal(const Eigen::Vector3d& point_in_image, const Eigen::Vector3d& normal) {
  return normal.y() > 0.35 && point_in_image.z() > -45.0 && point_in_image.z() < 85.0;
}

/// `count` points uniformly on the triangles where `keep(centroid, unit normal)` holds
/// (area-weighted, random barycentric), moved `noise_mm` (Gaussian sigma) along the normal, with
/// interpolated vertex normals; image frame.
template <typename Keep>
PointCloud SurfaceSamples(const TriangleMesh& skin, std::size_t count, double noise_mm,
                          std::mt19937_64& rng, Keep&& keep) {
  std::vector<int> kept;
  std::vector<double> cumulative_area;
  double total = 0.0;
  for (std::size_t t = 0; t < skin.triangles.size(); ++t) {
    const Eigen::Vector3i& tri = skin.triangles[t];
    const Eigen::Vector3d a = skin.vertices[static_cast<std::size_t>(tri(0))];
    const Eigen::Vector3d b = skin.vertices[static_cast<std::size_t>(tri(1))];
    const Eigen::Vector3d c = skin.vertices[static_cast<std::size_t>(tri(2))];
    const Eigen::Vector3d cross = (b - a).cross(c - a);
    if (cross.norm() < 1e-9 || !keep((a + b + c) / 3.0, cross.normalized())) continue;
    total += 0.5 * cross.norm();
    kept.push_back(static_cast<int>(t));
    cumulative_area.push_back(total);
  }
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  std::normal_distribution<double> gauss(0.0, 1.0);
  PointCloud cloud;
  for (std::size_t i = 0; i < count && !kept.empty(); ++i) {
    const auto pick =
        std::lower_bound(cumulative_area.begin(), cumulative_area.end(), uniform(rng) * total) -
        cumulative_area.begin();
    const Eigen::Vector3i& tri = skin.triangles[static_cast<std::size_t>(
        kept[static_cast<std::size_t>(std::min<std::ptrdiff_t>(pick, std::ssize(kept) - 1))])];
    double u = uniform(rng), v = uniform(rng);
    if (u + v > 1.0) u = 1.0 - u, v = 1.0 - v;
    const auto corner = [&](int k) { return static_cast<std::size_t>(tri(k)); };
    const Eigen::Vector3d point = (1.0 - u - v) * skin.vertices[corner(0)] +
                                  u * skin.vertices[corner(1)] + v * skin.vertices[corner(2)];
    const Eigen::Vector3d normal =
        ((1.0 - u - v) * skin.vertex_normals[corner(0)] + u * skin.vertex_normals[corner(1)] +
         v * skin.vertex_normals[corner(2)])
            .normalized();
    cloud.points.push_back(point + noise_mm * gauss(rng) * normal);
    cloud.normals.push_back(normal);
  }
  return cloud;
}

/// SurfaceSamples over the phantom's frontal triangles (IsFrontal).
inline PointCloud FrontalSamples(const TriangleMesh& skin, std::size_t count, double noise_mm,
                                 std::mt19937_64& rng) {
  return SurfaceSamples(skin, count, noise_mm, rng, IsFrontal);
}

/// The frontal vertices of the skin themselves (noise-free, exactly on the target's samples).
inline PointCloud FrontalVertices(const TriangleMesh& skin) {
  PointCloud cloud;
  for (std::size_t i = 0; i < skin.vertices.size(); ++i) {
    if (!IsFrontal(skin.vertices[i], skin.vertex_normals[i])) continue;
    cloud.points.push_back(skin.vertices[i]);
    cloud.normals.push_back(skin.vertex_normals[i]);
  }
  return cloud;
}

/// A rotation of uniformly random axis and angle in [0, max_angle_rad] and a translation uniform
/// in [-max_shift_mm, max_shift_mm] per axis.
inline Rigid3d RandomRigid(std::mt19937_64& rng, double max_angle_rad, double max_shift_mm) {
  std::normal_distribution<double> gauss(0.0, 1.0);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const Eigen::Vector3d axis = Eigen::Vector3d(gauss(rng), gauss(rng), gauss(rng)).normalized();
  const double angle_rad = max_angle_rad * 0.5 * (unit(rng) + 1.0);
  const Eigen::Vector3d shift_mm(unit(rng), unit(rng), unit(rng));
  return {Eigen::Quaterniond(Eigen::AngleAxisd(angle_rad, axis)), max_shift_mm * shift_mm};
}

/// Lighter search settings so unoptimised test builds stay well under a second per registration:
/// fewer anchors and rolls, fewer refined candidates. The defaults are exercised in Release by
/// bench/registration_bench.cpp (BM_AcceptanceSweep).
inline RegisterSurfaceOptions FastTestOptions() {
  RegisterSurfaceOptions options;
  options.sample_spacing_mm = 4.0;
  options.coarse.target_spacing_mm = 6.0;
  options.coarse.anchor_spacing_mm = 14.0;
  options.coarse.roll_steps = 12;
  options.coarse.score_samples = 32;
  options.coarse.refine_candidates = 24;
  options.coarse.refine_samples = 80;
  options.coarse.refine_gates_mm = {8.0, 4.0, 2.0};
  options.coarse.refine_iterations = 5;
  return options;
}

inline double Degrees(double radians) { return radians * 180.0 / std::numbers::pi; }

}  // namespace tofnav::test
