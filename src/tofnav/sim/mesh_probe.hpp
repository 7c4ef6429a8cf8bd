// SPDX-License-Identifier: BSD-3-Clause
// Exact ray queries against a triangle mesh (brute force: set-up time only, not per pixel).
#pragma once

#include <Eigen/Core>
#include <optional>

#include "tofnav/core/triangle_mesh.hpp"
#include "tofnav/sim/raycaster.hpp"
#include "tofnav/sim/scene.hpp"

namespace tofnav::sim {

struct MeshHit {
  double distance_mm = 0.0;  // along the unit direction
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // unit face normal (winding: outward)
};

/// Nearest hit with t > 0 of the ray origin + t * direction (direction normalised here), or
/// nullopt. Möller & Trumbore 1997 per triangle.
std::optional<MeshHit> IntersectMesh(const TriangleMesh& mesh, const Eigen::Vector3d& origin,
                                     const Eigen::Vector3d& direction);

/// Like IntersectMesh but throws PreconditionError naming `what` when nothing is hit.
MeshHit RequireMeshHit(const TriangleMesh& mesh, const Eigen::Vector3d& origin,
                       const Eigen::Vector3d& direction, const char* what);

/// Many rays from one origin against one mesh (Embree BVH, built once; a ray Embree misses,
/// e.g. through an edge, is retried exactly by IntersectMesh).
class MeshProbe {
 public:
  /// Keeps its own copy of `mesh`.
  MeshProbe(const TriangleMesh& mesh, const Eigen::Vector3d& origin);
  /// Nearest hit along `direction` from the origin; the normal is the interpolated vertex normal
  /// when the mesh has them.
  std::optional<MeshHit> Intersect(const Eigen::Vector3d& direction) const;
  /// Like Intersect but throws PreconditionError naming `what` when nothing is hit.
  MeshHit RequireHit(const Eigen::Vector3d& direction, const char* what) const;
  const Eigen::Vector3d& origin() const { return origin_; }

 private:
  static Scene OneObjectScene(const TriangleMesh& mesh);
  Eigen::Vector3d origin_;
  Scene scene_;
  SceneRaycaster raycaster_;
};

}  // namespace tofnav::sim
