// SPDX-License-Identifier: BSD-3-Clause
// An immutable KD-tree (nanoflann) over surface points with unit normals: the ICP target.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "tofnav/core/point_cloud.hpp"
#include "tofnav/core/triangle_mesh.hpp"

namespace tofnav {

struct SurfaceIndexOptions {
  int normal_neighbours = 16;  // k of the PCA normal estimate, used only when a cloud has none
  /// Estimated normals point towards this point (e.g. the camera) when given, else away from the
  /// centroid of the points (right for a closed head and for a face patch seen from outside).
  std::optional<Eigen::Vector3d> viewpoint;
  void Check() const;  // throws std::invalid_argument naming the field
};

/// One neighbour of a query: index into points()/normals() and squared distance [mm^2].
struct Neighbour {
  std::uint32_t index = 0;
  double distance_sq_mm2 = 0.0;
};

/// Points and unit normals in one frame (the variable name says which: `skin_in_image`), with a
/// KD-tree built once. Immutable, so it can be shared between threads and copied cheaply.
class SurfaceIndex {
 public:
  /// Takes the cloud's normals when it has them (they must be consistently oriented, e.g.
  /// outwards), else estimates them by PCA over `normal_neighbours` points. Points whose normal is
  /// zero or not finite are dropped. Throws PreconditionError when fewer than 3 points remain.
  explicit SurfaceIndex(PointCloud surface, const SurfaceIndexOptions& options = {});
  /// The same from points and normals (`normals` empty: estimated).
  SurfaceIndex(Points3d points, Points3d normals, const SurfaceIndexOptions& options = {});
  /// The mesh's vertex normals, or area-weighted ones from its triangles when it has none
  /// (vertices used by no triangle are dropped).
  explicit SurfaceIndex(const TriangleMesh& mesh);

  const Points3d& points() const;
  const Points3d& normals() const;
  std::size_t size() const { return points().size(); }
  /// Median distance from a point to its nearest other point [mm] (over at most 1000 points):
  /// a point on the surface can lie about this far from the nearest sample.
  double spacing_mm() const;

  /// The nearest point strictly closer than `max_distance_mm`, if any (bounded search: much
  /// faster than an unbounded one when the bound is tight).
  std::optional<Neighbour> Nearest(const Eigen::Vector3d& query, double max_distance_mm) const;
  /// Up to `k` (1 to kMaxNearestSet) nearest points strictly closer than `max_distance_mm`,
  /// closest first (in a tie, the one the search met first), and a lower bound on the distance of
  /// every other point [mm]: the (k+1)-th nearest's distance, or max_distance_mm when no more lie
  /// closer. While a query point moves by less than that bound minus its distance to a set point,
  /// no point outside the set can come nearer than that one.
  static constexpr int kMaxNearestSet = 8;
  struct NearestSet {
    std::array<Neighbour, kMaxNearestSet> nearest{};
    int count = 0;
    double others_from_mm = 0.0;
  };
  NearestSet NearestK(const Eigen::Vector3d& query, int k, double max_distance_mm) const;
  /// The k nearest points, closest first (fewer when the index is smaller than k).
  std::vector<Neighbour> KNearest(const Eigen::Vector3d& query, int k) const;
  /// Every point within `radius_mm`, closest first.
  std::vector<Neighbour> WithinRadius(const Eigen::Vector3d& query, double radius_mm) const;

 private:
  struct Impl;
  std::shared_ptr<const Impl> impl_;
};

}  // namespace tofnav
