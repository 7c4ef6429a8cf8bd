// SPDX-License-Identifier: BSD-3-Clause
// Analytic meshes for simulator scenes: boards, boxes, spheres and the paper's test shapes.
#pragma once

#include <Eigen/Core>
#include <array>

#include "tofnav/core/triangle_mesh.hpp"

namespace tofnav::sim {

/// Rectangle in the z = 0 plane centred on the origin, normal +z, width along x, height along y.
TriangleMesh PlaneMesh(double width_mm, double height_mm);
/// Closed axis-aligned box centred on the origin with edge lengths `size_mm` (flat faces).
TriangleMesh BoxMesh(const Eigen::Vector3d& size_mm);
/// Closed latitude-longitude sphere centred on the origin with exact vertex normals.
/// `segments` around the equator (>= 8); the chord sag is radius * (1 - cos(pi / segments)).
TriangleMesh SphereMesh(double radius_mm, int segments = 96);
/// Closed capsule (a cylinder with hemispherical ends) along x, centred on the origin, with exact
/// vertex normals: `length_mm` end to end (>= the diameter), `segments` around (even, >= 8).
TriangleMesh CapsuleMesh(double diameter_mm, double length_mm, int segments = 32);

/// The paper's 3D-printed test shapes (Sec. IV-A), standing on z = 0 and extending along +z.
enum class TestShape {
  kTriangularPyramid,  // regular tetrahedron, every edge = size
  kFrustumPyramid,     // square base of side = size, top side size / 2, height size / 3
  kHemisphere,         // diameter = size, closed by a flat base
};
/// The four sizes of the paper: longest edge > 100 (120), 60, 35 and 20 mm.
inline constexpr std::array<double, 4> kTestShapeSizesMm = {120.0, 60.0, 35.0, 20.0};

/// Closed mesh of a test shape whose longest edge (hemisphere: diameter) is `size_mm`.
TriangleMesh TestShapeMesh(TestShape shape, double size_mm);

}  // namespace tofnav::sim
