// SPDX-License-Identifier: BSD-3-Clause
// First-hit ray casting of a simulator scene from the AHAT optical centre (Embree 3 inside).
#pragma once

#include <Eigen/Core>
#include <memory>
#include <span>

#include "tofnav/core/rigid3d.hpp"
#include "tofnav/sim/scene.hpp"

namespace tofnav::sim {

/// The first surface along a ray, in the `ahat` frame.
struct RayHit {
  double range_mm = 0.0;  // distance from the optical centre along the unit ray
  Eigen::Vector3d normal_in_ahat = Eigen::Vector3d::Zero();  // unit outward (shading) normal
  int material = -1;  // index into Scene::materials; -1 = no hit
  int object = -1;    // index into Scene::objects, or -1 for a marker
  int tool = -1;      // marker hits: index into Scene::tools
  int marker = -1;    // marker hits: index within the tool
  bool hit() const { return material >= 0; }
};

/// Embree scene built once from a Scene: one BVH per object and per tool, joined by instances,
/// so a new pose only updates instance transforms. Hit ranges and normals are recomputed in
/// double precision on the exact primitive (triangle plane, sphere, disc).
class SceneRaycaster {
 public:
  /// Builds the BVHs; objects and tools start at their poses in `scene` seen from the identity.
  explicit SceneRaycaster(const Scene& scene);
  ~SceneRaycaster();
  SceneRaycaster(SceneRaycaster&&) noexcept;
  SceneRaycaster& operator=(SceneRaycaster&&) noexcept;
  SceneRaycaster(const SceneRaycaster&) = delete;
  SceneRaycaster& operator=(const SceneRaycaster&) = delete;

  /// Moves every object and tool to its pose in `scene`, seen from a camera at scene_from_ahat.
  /// `scene` must hold the same objects, meshes and markers as at construction (poses may differ).
  void SetPoses(const Scene& scene, const Rigid3d& scene_from_ahat);

  /// First hits of rays from the `ahat` origin along unit `directions_in_ahat`. Thread-safe.
  void Intersect(std::span<const Eigen::Vector3d> directions_in_ahat, std::span<RayHit> hits) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace tofnav::sim
