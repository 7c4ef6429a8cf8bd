// SPDX-License-Identifier: BSD-3-Clause
// The rasteriser against hand-computed coverage, depth order, shading and camera fits.
#include "tofnav/report/mesh_render.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace tofnav {
namespace {

constexpr double kExactTol = 1e-12;  // closed-form camera entries
constexpr double kOnEdgeTol = 1e-9;  // pixel centres this close to an edge may go either way
constexpr int kColourTol = 1;        // 8-bit rounding of the shaded colour

TriangleMesh OneTriangle(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                         const Eigen::Vector3d& c) {
  TriangleMesh mesh;
  mesh.vertices = {a, b, c};
  mesh.triangles = {Eigen::Vector3i(0, 1, 2)};
  return mesh;
}

// Identity rotation, 1 px per mm, centred: pixel (u, v) = (x + 10, y + 10) on a 20x20 image.
const RenderOptions kFlat{.width_px = 20, .height_px = 20, .ambient = 1.0};

TEST(RenderMeshes, CoversExactlyThePixelCentresInsideATriangle) {
  const TriangleMesh mesh = OneTriangle({-5, -5, 0}, {5, -5, 0}, {-5, 5, 0});
  const Rgb8 red(255, 0, 0);
  const MeshLayer layers[] = {{.mesh = &mesh, .colour = red}};
  const Image<Rgb8> image = RenderMeshes(layers, OrthoCamera{}, kFlat);
  int inside = 0;
  for (int v = 0; v < 20; ++v) {
    for (int u = 0; u < 20; ++u) {
      const double x = u + 0.5 - 10.0;
      const double y = v + 0.5 - 10.0;
      const double margin = std::min({x + 5.0, y + 5.0, -(x + y)});  // > 0 strictly inside
      if (std::abs(margin) < kOnEdgeTol) continue;
      const Rgb8 expected = margin > 0 ? red : kFlat.background;
      inside += margin > 0;
      EXPECT_EQ(image(u, v), expected) << "pixel (" << u << ", " << v << ")";
    }
  }
  EXPECT_EQ(inside, 45);  // pixels with u, v >= 5 and u + v <= 18
}

TEST(RenderMeshes, NearestSurfaceWinsInEitherOrder) {
  const TriangleMesh far = OneTriangle({-8, -8, 0}, {8, -8, 0}, {-8, 8, 0});
  const TriangleMesh near = OneTriangle({-8, -8, 2}, {8, -8, 2}, {-8, 8, 2});
  const Rgb8 red(255, 0, 0), green(0, 255, 0);
  const MeshLayer far_first[] = {{.mesh = &far, .colour = red}, {.mesh = &near, .colour = green}};
  const MeshLayer near_first[] = {{.mesh = &near, .colour = green}, {.mesh = &far, .colour = red}};
  EXPECT_EQ(RenderMeshes(far_first, OrthoCamera{}, kFlat)(6, 6), green);
  EXPECT_EQ(RenderMeshes(near_first, OrthoCamera{}, kFlat)(6, 6), green);
  // A depth offset larger than the 2 mm gap brings the far layer to the front.
  const MeshLayer offset[] = {{.mesh = &near, .colour = green},
                              {.mesh = &far, .colour = red, .depth_offset_mm = 3.0}};
  EXPECT_EQ(RenderMeshes(offset, OrthoCamera{}, kFlat)(6, 6), red);
}

TEST(RenderMeshes, ShadesByTheCosineToTheViewer) {
  constexpr double kAmbient = 0.3;
  const RenderOptions options{.width_px = 20, .height_px = 20, .ambient = kAmbient};
  const Rgb8 grey(200, 200, 200);
  // Facing the viewer (+z): full colour. Tilted 60 degrees about x: cos = 0.5.
  const TriangleMesh facing = OneTriangle({-8, -8, 0}, {8, -8, 0}, {-8, 8, 0});
  const double c = std::cos(std::numbers::pi / 3), s = std::sin(std::numbers::pi / 3);
  const TriangleMesh tilted =
      OneTriangle({-8, -8 * c, -8 * s}, {8, -8 * c, -8 * s}, {-8, 8 * c, 8 * s});
  const MeshLayer a[] = {{.mesh = &facing, .colour = grey}};
  const MeshLayer b[] = {{.mesh = &tilted, .colour = grey}};
  EXPECT_NEAR(RenderMeshes(a, OrthoCamera{}, options)(6, 8)[0], 200, kColourTol);
  EXPECT_NEAR(RenderMeshes(b, OrthoCamera{}, options)(6, 8)[0], 200 * (kAmbient + 0.7 * 0.5),
              kColourTol);
}

TEST(OrbitCamera, LooksFromMinusYWithZUpAndFitsTheBoundingSphere) {
  TriangleMesh cube = OneTriangle({-1, -1, -1}, {1, 1, 1}, {1, -1, 1});
  for (Eigen::Vector3d& p : cube.vertices) p += Eigen::Vector3d(10, 20, 30);
  const MeshLayer layers[] = {{.mesh = &cube}};
  const RenderOptions options{.width_px = 200, .height_px = 100};
  const OrthoCamera camera = OrbitCamera(layers, 0.0, 0.0, options);
  EXPECT_TRUE(camera.rotation.row(0).isApprox(Eigen::RowVector3d(1, 0, 0), kExactTol));
  EXPECT_TRUE(camera.rotation.row(1).isApprox(Eigen::RowVector3d(0, 0, -1), kExactTol));
  EXPECT_TRUE(camera.rotation.row(2).isApprox(Eigen::RowVector3d(0, -1, 0), kExactTol));
  EXPECT_TRUE(camera.centre_mm.isApprox(Eigen::Vector3d(10, 20, 30), kExactTol));
  EXPECT_NEAR(camera.pixels_per_mm, 50.0 * 0.9 / std::sqrt(3.0), kExactTol);  // 5 % margins
}

TEST(ErrorColour, RunsFromDarkBlueToRedAndClamps) {
  EXPECT_EQ(ErrorColour(0.0), Rgb8(20, 40, 160));
  EXPECT_EQ(ErrorColour(1.0), Rgb8(210, 30, 30));
  EXPECT_EQ(ErrorColour(-3.0), ErrorColour(0.0));
  EXPECT_EQ(ErrorColour(7.0), ErrorColour(1.0));
  EXPECT_EQ(ErrorColour(std::nan("")), ErrorColour(0.0));
}

TEST(RenderOptions, RejectsAnEmptyImage) {
  EXPECT_THROW(RenderOptions{.width_px = 0}.Check(), PreconditionError);
}

}  // namespace
}  // namespace tofnav
