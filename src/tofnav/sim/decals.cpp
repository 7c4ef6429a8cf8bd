// SPDX-License-Identifier: BSD-3-Clause
// Tape stickers drawn on an object's surface.
#include "tofnav/sim/decals.hpp"

#include <cmath>

namespace tofnav::sim {

std::vector<std::vector<Decal>> CollectDecals(const Scene& scene) {
  std::vector<std::vector<Decal>> decals(scene.objects.size());
  for (int t = 0; t < static_cast<int>(scene.tools.size()); ++t) {
    const Tool& tool = scene.tools[static_cast<std::size_t>(t)];
    for (int m = 0; m < static_cast<int>(tool.markers.size()); ++m) {
      const Marker& marker = tool.markers[static_cast<std::size_t>(m)];
      if (marker.conforms_to_object < 0) continue;
      Decal decal;
      decal.tool = t;
      decal.marker = m;
      decal.radius_mm = 0.5 * marker.diameter_mm;
      decal.material = marker.material;
      decals[static_cast<std::size_t>(marker.conforms_to_object)].push_back(decal);
    }
  }
  return decals;
}

void PlaceDecals(const Scene& scene, std::vector<std::vector<Decal>>& decals) {
  for (std::size_t o = 0; o < decals.size(); ++o) {
    const Rigid3d object_from_scene = scene.objects[o].scene_from_object.Inverse();
    for (Decal& decal : decals[o]) {
      const Tool& tool = scene.tools[static_cast<std::size_t>(decal.tool)];
      const Marker& marker = tool.markers[static_cast<std::size_t>(decal.marker)];
      const Rigid3d object_from_tool = object_from_scene * tool.scene_from_tool;
      decal.centre_in_object = object_from_tool * marker.centre_in_tool;
      decal.normal_in_object = object_from_tool.rotation * marker.normal_in_tool.normalized();
    }
  }
}

const Decal* FindDecal(std::span<const Decal> decals, const Eigen::Vector3d& point_in_object) {
  for (const Decal& decal : decals) {
    const Eigen::Vector3d offset = point_in_object - decal.centre_in_object;
    const double height = decal.normal_in_object.dot(offset);
    if (std::abs(height) <= decal.radius_mm &&
        (offset - height * decal.normal_in_object).norm() <= decal.radius_mm) {
      return &decal;
    }
  }
  return nullptr;
}

}  // namespace tofnav::sim
