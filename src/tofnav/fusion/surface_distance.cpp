// SPDX-License-Identifier: BSD-3-Clause
// Exact point-to-triangle-mesh distances through a uniform grid of triangles (evaluation).
#include "tofnav/fusion/surface_distance.hpp"

#include <cmath>
#include <limits>

#include "tofnav/core/require.hpp"

namespace tofnav {

Eigen::Vector3d ClosestPointOnTriangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                       const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0.0 && d2 <= 0.0) return a;  // vertex region A
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0.0 && d4 <= d3) return b;  // vertex region B
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) return a + d1 / (d1 - d3) * ab;  // edge AB
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0.0 && d5 <= d6) return c;  // vertex region C
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) return a + d2 / (d2 - d6) * ac;  // edge AC
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {  // edge BC
    return b + (d4 - d3) / ((d4 - d3) + (d5 - d6)) * (c - b);
  }
  const double denom = va + vb + vc;
  if (!(std::abs(denom) > 0.0)) return a;            // degenerate triangle
  return a + ab * (vb / denom) + ac * (vc / denom);  // inside the face
}

SurfaceDistance::SurfaceDistance(const TriangleMesh& mesh, double cell_mm)
    : mesh_(mesh), cell_mm_(cell_mm) {
  mesh.CheckConsistent();
  Require(std::isfinite(cell_mm) && cell_mm > 0.0, "SurfaceDistance: cell_mm must be > 0");
  face_normals_.reserve(mesh.triangles.size());
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const Eigen::Vector3i& tri = mesh.triangles[t];
    const Eigen::Vector3d& a = mesh.vertices[static_cast<std::size_t>(tri[0])];
    const Eigen::Vector3d& b = mesh.vertices[static_cast<std::size_t>(tri[1])];
    const Eigen::Vector3d& c = mesh.vertices[static_cast<std::size_t>(tri[2])];
    face_normals_.push_back((b - a).cross(c - a).normalized());
    const Eigen::Vector3i lo = Cell(a.cwiseMin(b).cwiseMin(c));
    const Eigen::Vector3i hi = Cell(a.cwiseMax(b).cwiseMax(c));
    for (int z = lo.z(); z <= hi.z(); ++z) {
      for (int y = lo.y(); y <= hi.y(); ++y) {
        for (int x = lo.x(); x <= hi.x(); ++x) {
          cells_[Key({x, y, z})].push_back(static_cast<int>(t));
        }
      }
    }
  }
}

Eigen::Vector3i SurfaceDistance::Cell(const Eigen::Vector3d& p) const {
  return (p / cell_mm_).array().floor().cast<int>();
}

std::uint64_t SurfaceDistance::Key(const Eigen::Vector3i& cell) {
  const auto field = [](int c) { return static_cast<std::uint64_t>(c + (1 << 20)) & 0x1fffff; };
  return (field(cell.x()) << 42) | (field(cell.y()) << 21) | field(cell.z());
}

std::optional<SurfacePoint> SurfaceDistance::Closest(const Eigen::Vector3d& query,
                                                     double max_distance_mm) const {
  const Eigen::Vector3i centre = Cell(query);
  const int rings = static_cast<int>(std::ceil(max_distance_mm / cell_mm_)) + 1;
  double best2 = max_distance_mm * max_distance_mm;
  SurfacePoint best;
  for (int k = 0; k <= rings; ++k) {
    for (int z = -k; z <= k; ++z) {
      for (int y = -k; y <= k; ++y) {
        for (int x = -k; x <= k; ++x) {
          if (std::max({std::abs(x), std::abs(y), std::abs(z)}) != k) continue;  // ring k only
          const auto it = cells_.find(Key(centre + Eigen::Vector3i(x, y, z)));
          if (it == cells_.end()) continue;
          for (const int t : it->second) {
            const Eigen::Vector3i& tri = mesh_.triangles[static_cast<std::size_t>(t)];
            const Eigen::Vector3d q =
                ClosestPointOnTriangle(query, mesh_.vertices[static_cast<std::size_t>(tri[0])],
                                       mesh_.vertices[static_cast<std::size_t>(tri[1])],
                                       mesh_.vertices[static_cast<std::size_t>(tri[2])]);
            const double d2 = (query - q).squaredNorm();
            if (d2 <= best2 && (best.triangle < 0 || d2 < best2 || t < best.triangle)) {
              best2 = d2;
              best.point = q;
              best.triangle = t;
            }
          }
        }
      }
    }
    // Every cell of ring k + 1 is at least k cells away from the query.
    if (best.triangle >= 0 && best2 <= std::pow(k * cell_mm_, 2)) break;
  }
  if (best.triangle < 0) return std::nullopt;
  best.distance_mm = std::sqrt(best2);
  const double side =
      (query - best.point).dot(face_normals_[static_cast<std::size_t>(best.triangle)]);
  best.signed_distance_mm = side < 0.0 ? -best.distance_mm : best.distance_mm;
  return best;
}

}  // namespace tofnav
