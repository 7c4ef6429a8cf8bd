// SPDX-License-Identifier: BSD-3-Clause
// Simulator scenes.
#include "tofnav/sim/scene.hpp"

#include <cmath>
#include <utility>

#include "tofnav/core/require.hpp"

namespace tofnav::sim {

int Scene::AddMaterial(Material material) {
  material.Check();
  materials.push_back(std::move(material));
  return static_cast<int>(materials.size()) - 1;
}

int Scene::AddObject(std::string name, TriangleMesh mesh, int material,
                     const Rigid3d& scene_from_object) {
  objects.push_back({std::move(name), std::move(mesh), material, scene_from_object});
  return static_cast<int>(objects.size()) - 1;
}

int Scene::AddTool(Tool tool) {
  tools.push_back(std::move(tool));
  return static_cast<int>(tools.size()) - 1;
}

int Scene::MarkerId(int tool, int marker) const {
  Require(tool >= 0 && tool < static_cast<int>(tools.size()), "Scene::MarkerId: bad tool index");
  Require(marker >= 0 &&
              marker < static_cast<int>(tools[static_cast<std::size_t>(tool)].markers.size()),
          "Scene::MarkerId: bad marker index");
  int id = 0;
  for (int t = 0; t < tool; ++t)
    id += static_cast<int>(tools[static_cast<std::size_t>(t)].markers.size());
  return id + marker;
}

void Scene::Check() const {
  const int material_count = static_cast<int>(materials.size());
  for (const Material& material : materials) material.Check();
  for (const SceneObject& object : objects) {
    Require(object.material >= 0 && object.material < material_count,
            "Scene: object '" + object.name + "' has a bad material index");
    object.mesh.CheckConsistent();
  }
  for (const Tool& tool : tools) {
    for (const Marker& marker : tool.markers) {
      Require(marker.material >= 0 && marker.material < material_count,
              "Scene: a marker of tool '" + tool.name + "' has a bad material index");
      Require(marker.diameter_mm > 0.0 && std::isfinite(marker.diameter_mm),
              "Scene: marker diameter must be positive");
      Require(marker.centre_in_tool.allFinite(), "Scene: marker centre must be finite");
      Require(marker.shape != MarkerShape::kDisc || marker.normal_in_tool.norm() > 0.5,
              "Scene: disc marker normal must be a unit vector");
      Require(marker.conforms_to_object < static_cast<int>(objects.size()) &&
                  (marker.conforms_to_object < 0 || marker.shape == MarkerShape::kDisc),
              "Scene: a conforming marker of tool '" + tool.name +
                  "' must be a disc on an existing object");
    }
  }
}

Marker SphereMarker(const Eigen::Vector3d& centre_in_tool, double diameter_mm, int material) {
  return {MarkerShape::kSphere, diameter_mm, centre_in_tool, Eigen::Vector3d::UnitZ(), material};
}

Marker DiscMarkerOnSurface(const Eigen::Vector3d& point_in_tool,
                           const Eigen::Vector3d& normal_in_tool, double diameter_mm, int material,
                           double offset_mm) {
  const Eigen::Vector3d normal = normal_in_tool.normalized();
  return {MarkerShape::kDisc, diameter_mm, point_in_tool + offset_mm * normal, normal, material};
}

}  // namespace tofnav::sim
