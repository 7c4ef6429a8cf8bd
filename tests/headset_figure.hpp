// SPDX-License-Identifier: BSD-3-Clause
// A picture of what the headset wearer sees: the fake remote scene's active holograms over the
// patient's skin, seen from the wearer's head (orthographic; text panels are not drawn).
#pragma once

#include <algorithm>
#include <filesystem>
#include <vector>

#include "tofnav/io/file.hpp"
#include "tofnav/report/mesh_render.hpp"
#include "tofnav/report/png.hpp"
#include "tofnav/sim/shapes.hpp"
#include "tofnav/stream_testing/fake_remote_scene_server.hpp"

namespace tofnav::testing {

inline Rgb8 Blend(const Rgba& c) {  // over a white background
  const auto channel = [&](float v) {
    return static_cast<std::uint8_t>(std::clamp(255.0f * (c.a * v + 1.0f - c.a), 0.0f, 255.0f));
  };
  return Rgb8(channel(c.r), channel(c.g), channel(c.b));
}

/// Writes a PNG of `scene` with `skin_in_world` seen from `eye_in_world` towards `centre_in_world`
/// (+y up), `width_mm` across.
inline void WriteHeadsetFigure(const std::filesystem::path& path, const FakeRemoteScene& scene,
                               const TriangleMesh& skin_in_world,
                               const Eigen::Vector3d& eye_in_world,
                               const Eigen::Vector3d& centre_in_world, double width_mm) {
  std::vector<TriangleMesh> meshes;
  std::vector<Rgb8> colours;
  meshes.reserve(scene.objects.size() + 1);
  meshes.push_back(skin_in_world);
  colours.push_back(Rgb8(225, 200, 180));
  for (const auto& [key, o] : scene.objects) {
    if (!o.active || o.is_text) continue;
    if (o.primitive == UnityPrimitive::kSphere) {
      const Eigen::Vector3d centre = WorldFromUnityPoint(o.transform.position_m.cast<double>());
      meshes.push_back(Transform(Rigid3d(Eigen::Quaterniond::Identity(), centre),
                                 sim::SphereMesh(500.0 * o.transform.scale.x(), 24)));
    } else {  // cylinders as thin square bars along their axis
      const auto [a, b] = WorldCylinderEnds(o.transform);
      const double d = 1000.0 * o.transform.scale.x();
      const Eigen::Quaterniond along =
          Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), b - a);
      meshes.push_back(
          Transform(Rigid3d(along, 0.5 * (a + b)), sim::BoxMesh({d, d, (b - a).norm()})));
    }
    colours.push_back(Blend(o.colour));
  }
  std::vector<MeshLayer> layers;
  for (std::size_t i = 0; i < meshes.size(); ++i) {
    // Holograms overlay the real head (no occlusion by it), as in the headset.
    layers.push_back({&meshes[i], {}, colours[i], i == 0 ? 0.0 : 1000.0});
  }
  const Eigen::Vector3d toward = (eye_in_world - centre_in_world).normalized();
  const Eigen::Vector3d right = Eigen::Vector3d::UnitY().cross(toward).normalized();
  const Eigen::Vector3d down = right.cross(toward);
  OrthoCamera camera;
  camera.rotation.row(0) = right.transpose();
  camera.rotation.row(1) = down.transpose();
  camera.rotation.row(2) = toward.transpose();
  camera.centre_mm = centre_in_world;
  RenderOptions options;
  options.width_px = 640;
  options.height_px = 480;
  camera.pixels_per_mm = options.width_px / width_mm;
  WriteFileAtomically(path, EncodePng(RenderMeshes(layers, camera, options)));
}

}  // namespace tofnav::testing
