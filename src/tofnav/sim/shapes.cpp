// SPDX-License-Identifier: BSD-3-Clause
// Analytic meshes for simulator scenes.
#include "tofnav/sim/shapes.hpp"

#include <cmath>
#include <numbers>
#include <utility>

#include "tofnav/core/require.hpp"

namespace tofnav::sim {
namespace {

// Flips triangles of a convex mesh whose normal points towards the centroid.
void OrientOutward(TriangleMesh& mesh) {
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : mesh.vertices) centroid += p;
  centroid /= static_cast<double>(mesh.vertices.size());
  for (Eigen::Vector3i& t : mesh.triangles) {
    const Eigen::Vector3d& a = mesh.vertices[static_cast<std::size_t>(t[0])];
    const Eigen::Vector3d& b = mesh.vertices[static_cast<std::size_t>(t[1])];
    const Eigen::Vector3d& c = mesh.vertices[static_cast<std::size_t>(t[2])];
    if ((b - a).cross(c - a).dot((a + b + c) / 3.0 - centroid) < 0.0) std::swap(t[1], t[2]);
  }
}

// Convex polyhedron from its vertices and its (convex, planar) faces as vertex loops.
TriangleMesh ConvexPolyhedron(Points3d vertices, const std::vector<std::vector<int>>& faces) {
  TriangleMesh mesh;
  mesh.vertices = std::move(vertices);
  for (const std::vector<int>& face : faces) {
    for (std::size_t k = 1; k + 1 < face.size(); ++k) {
      mesh.triangles.emplace_back(face[0], face[k], face[k + 1]);
    }
  }
  OrientOutward(mesh);
  return mesh;
}

// Latitude-longitude grid: polar angle 0 .. polar_max_rad over `rings` rings, `segments` around.
// Adds the vertices (unit directions scaled by radius, exact normals) and CCW-outward triangles.
void AddSphereCap(TriangleMesh& mesh, double radius_mm, int segments, int rings,
                  double polar_max_rad, bool close_south_pole) {
  const int first = static_cast<int>(mesh.vertices.size());
  mesh.vertices.push_back({0.0, 0.0, radius_mm});
  mesh.vertex_normals.push_back(Eigen::Vector3d::UnitZ());
  for (int i = 1; i <= rings; ++i) {
    if (i == rings && close_south_pole) break;
    const double polar = polar_max_rad * i / rings;
    for (int j = 0; j < segments; ++j) {
      const double azimuth = 2.0 * std::numbers::pi * j / segments;
      const Eigen::Vector3d n(std::sin(polar) * std::cos(azimuth),
                              std::sin(polar) * std::sin(azimuth), std::cos(polar));
      mesh.vertices.push_back(radius_mm * n);
      mesh.vertex_normals.push_back(n);
    }
  }
  const auto ring_vertex = [&](int i, int j) {
    return first + 1 + (i - 1) * segments + j % segments;
  };
  for (int j = 0; j < segments; ++j)
    mesh.triangles.emplace_back(first, ring_vertex(1, j), ring_vertex(1, j + 1));
  const int last_ring = close_south_pole ? rings - 1 : rings;
  for (int i = 1; i < last_ring; ++i) {
    for (int j = 0; j < segments; ++j) {
      const int a = ring_vertex(i, j), b = ring_vertex(i + 1, j);
      const int c = ring_vertex(i + 1, j + 1), d = ring_vertex(i, j + 1);
      mesh.triangles.emplace_back(a, b, c);
      mesh.triangles.emplace_back(a, c, d);
    }
  }
  if (close_south_pole) {
    const int pole = static_cast<int>(mesh.vertices.size());
    mesh.vertices.push_back({0.0, 0.0, -radius_mm});
    mesh.vertex_normals.push_back(-Eigen::Vector3d::UnitZ());
    for (int j = 0; j < segments; ++j) {
      mesh.triangles.emplace_back(pole, ring_vertex(last_ring, j + 1), ring_vertex(last_ring, j));
    }
  }
}

TriangleMesh Hemisphere(double radius_mm, int segments) {
  TriangleMesh mesh;
  AddSphereCap(mesh, radius_mm, segments, segments / 4, 0.5 * std::numbers::pi, false);
  // Flat base with its own vertices (normal -z), a fan around the centre.
  const int centre = static_cast<int>(mesh.vertices.size());
  mesh.vertices.push_back(Eigen::Vector3d::Zero());
  mesh.vertex_normals.push_back(-Eigen::Vector3d::UnitZ());
  for (int j = 0; j < segments; ++j) {
    const double azimuth = 2.0 * std::numbers::pi * j / segments;
    mesh.vertices.push_back({radius_mm * std::cos(azimuth), radius_mm * std::sin(azimuth), 0.0});
    mesh.vertex_normals.push_back(-Eigen::Vector3d::UnitZ());
  }
  for (int j = 0; j < segments; ++j) {
    mesh.triangles.emplace_back(centre, centre + 1 + (j + 1) % segments, centre + 1 + j);
  }
  return mesh;
}

}  // namespace

TriangleMesh PlaneMesh(double width_mm, double height_mm) {
  Require(width_mm > 0.0 && height_mm > 0.0, "PlaneMesh: size must be positive");
  const double x = 0.5 * width_mm, y = 0.5 * height_mm;
  TriangleMesh mesh;
  mesh.vertices = {{-x, -y, 0.0}, {x, -y, 0.0}, {x, y, 0.0}, {-x, y, 0.0}};
  mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
  return mesh;
}

TriangleMesh BoxMesh(const Eigen::Vector3d& size_mm) {
  Require((size_mm.array() > 0.0).all(), "BoxMesh: size must be positive");
  const Eigen::Vector3d h = 0.5 * size_mm;
  Points3d v;
  for (int k = 0; k < 8; ++k) {
    v.emplace_back((k & 1) ? h.x() : -h.x(), (k & 2) ? h.y() : -h.y(), (k & 4) ? h.z() : -h.z());
  }
  return ConvexPolyhedron(
      std::move(v),
      {{0, 1, 3, 2}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 3, 7, 6}, {0, 2, 6, 4}, {1, 3, 7, 5}});
}

TriangleMesh SphereMesh(double radius_mm, int segments) {
  Require(radius_mm > 0.0, "SphereMesh: radius must be positive");
  Require(segments >= 8 && segments % 2 == 0, "SphereMesh: segments must be even and >= 8");
  TriangleMesh mesh;
  AddSphereCap(mesh, radius_mm, segments, segments / 2, std::numbers::pi, true);
  return mesh;
}

TriangleMesh CapsuleMesh(double diameter_mm, double length_mm, int segments) {
  Require(diameter_mm > 0.0 && length_mm >= diameter_mm,
          "CapsuleMesh: need 0 < diameter_mm <= length_mm");
  Require(segments >= 8 && segments % 2 == 0, "CapsuleMesh: segments must be even and >= 8");
  const double radius = 0.5 * diameter_mm, half_cylinder = 0.5 * (length_mm - diameter_mm);
  const int quarter = segments / 4;  // rings per hemisphere
  TriangleMesh mesh;
  // Built along z, then (a, b, c) -> (c, a, b): a cyclic permutation, so a rotation.
  const auto add = [&](const Eigen::Vector3d& n, double shift) {
    const Eigen::Vector3d p = radius * n + Eigen::Vector3d(0.0, 0.0, shift);
    mesh.vertices.emplace_back(p.z(), p.x(), p.y());
    mesh.vertex_normals.emplace_back(n.z(), n.x(), n.y());
  };
  add(Eigen::Vector3d::UnitZ(), half_cylinder);
  // Rings 1..quarter on the +z cap down to its equator, then quarter..2 quarter - 1 on the -z cap.
  const int rings = 2 * quarter;
  for (int k = 1; k <= rings; ++k) {
    const int i = k <= quarter ? k : k - 1;
    const double polar = 0.5 * std::numbers::pi * i / quarter;
    for (int j = 0; j < segments; ++j) {
      const double azimuth = 2.0 * std::numbers::pi * j / segments;
      add({std::sin(polar) * std::cos(azimuth), std::sin(polar) * std::sin(azimuth),
           std::cos(polar)},
          k <= quarter ? half_cylinder : -half_cylinder);
    }
  }
  add(-Eigen::Vector3d::UnitZ(), -half_cylinder);
  const int south = static_cast<int>(mesh.vertices.size()) - 1;
  const auto ring = [&](int k, int j) { return 1 + (k - 1) * segments + j % segments; };
  for (int j = 0; j < segments; ++j) {
    mesh.triangles.emplace_back(0, ring(1, j), ring(1, j + 1));
    mesh.triangles.emplace_back(south, ring(rings, j + 1), ring(rings, j));
  }
  for (int k = 1; k < rings; ++k) {
    for (int j = 0; j < segments; ++j) {
      const int a = ring(k, j), b = ring(k + 1, j), c = ring(k + 1, j + 1), d = ring(k, j + 1);
      mesh.triangles.emplace_back(a, b, c);
      mesh.triangles.emplace_back(a, c, d);
    }
  }
  return mesh;
}

TriangleMesh TestShapeMesh(TestShape shape, double size_mm) {
  Require(size_mm > 0.0, "TestShapeMesh: size must be positive");
  const double s = size_mm;
  switch (shape) {
    case TestShape::kTriangularPyramid: {
      const double r = s / std::sqrt(3.0);  // circumradius of the equilateral base
      Points3d v;
      for (int k = 0; k < 3; ++k) {
        const double a = 2.0 * std::numbers::pi * k / 3.0;
        v.emplace_back(r * std::cos(a), r * std::sin(a), 0.0);
      }
      v.emplace_back(0.0, 0.0, s * std::sqrt(2.0 / 3.0));
      return ConvexPolyhedron(std::move(v), {{0, 1, 2}, {0, 1, 3}, {1, 2, 3}, {2, 0, 3}});
    }
    case TestShape::kFrustumPyramid: {
      const double b = 0.5 * s, t = 0.25 * s, h = s / 3.0;
      Points3d v = {{-b, -b, 0}, {b, -b, 0}, {b, b, 0}, {-b, b, 0},
                    {-t, -t, h}, {t, -t, h}, {t, t, h}, {-t, t, h}};
      return ConvexPolyhedron(
          std::move(v),
          {{0, 1, 2, 3}, {4, 5, 6, 7}, {0, 1, 5, 4}, {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}});
    }
    case TestShape::kHemisphere:
      return Hemisphere(0.5 * s, 96);
  }
  Require(false, "TestShapeMesh: unknown shape");
  return {};
}

}  // namespace tofnav::sim
