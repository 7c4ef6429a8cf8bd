// SPDX-License-Identifier: BSD-3-Clause
// Exact point-to-triangle-mesh distances through a uniform grid of triangles (evaluation).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <unordered_map>
#include <vector>

#include "tofnav/core/triangle_mesh.hpp"

namespace tofnav {

struct SurfacePoint {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();  // closest point on the mesh [mm]
  double distance_mm = 0.0;                         // |query - point|
  /// distance_mm with the sign of (query - point) . face normal: positive in front of the face
  /// (outside, for a mesh wound counter-clockwise seen from outside).
  double signed_distance_mm = 0.0;
  int triangle = -1;
};

/// The closest point of a triangle (Ericson 2005, section 5.1.5, by Voronoi regions).
Eigen::Vector3d ClosestPointOnTriangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                       const Eigen::Vector3d& b, const Eigen::Vector3d& c);

/// A mesh with its triangles binned in cubic cells, for many closest-point queries. Queries
/// search rings of cells outwards and stop as soon as no unvisited cell can be nearer, so the
/// answer is exact within the search radius. Thread-safe for concurrent queries.
class SurfaceDistance {
 public:
  /// Keeps a copy of the mesh. Throws PreconditionError on an inconsistent mesh or cell <= 0.
  explicit SurfaceDistance(const TriangleMesh& mesh, double cell_mm = 4.0);

  /// The closest point within max_distance_mm of `query`, or nullopt when there is none.
  std::optional<SurfacePoint> Closest(const Eigen::Vector3d& query, double max_distance_mm) const;
  const TriangleMesh& mesh() const { return mesh_; }

 private:
  Eigen::Vector3i Cell(const Eigen::Vector3d& p) const;
  static std::uint64_t Key(const Eigen::Vector3i& cell);

  TriangleMesh mesh_;
  std::vector<Eigen::Vector3d> face_normals_;
  double cell_mm_ = 4.0;
  std::unordered_map<std::uint64_t, std::vector<int>> cells_;
};

}  // namespace tofnav
