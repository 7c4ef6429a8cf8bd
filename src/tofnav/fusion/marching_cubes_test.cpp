// SPDX-License-Identifier: BSD-3-Clause
#include "tofnav/fusion/marching_cubes.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <random>

#include "tofnav/fusion/marching_cubes_tables.hpp"
#include "tofnav/fusion/mesh_test_util.hpp"

namespace tofnav {
namespace {

constexpr double kAreaRelTol = 0.01;  // the bound for the dense sphere
// Linear interpolation of a sphere's exact SDF along 1 mm edges: error ~ h^2 / (2 R) = 0.025 mm.
constexpr double kSdfVertexTolMm = 0.03;

/// Signed distance to a sphere sampled on a grid; frame_from_ijk maps indices to mm.
Grid3<float> SphereSdf(const Eigen::Vector3i& dims, const Eigen::Matrix4d& frame_from_ijk,
                       const Eigen::Vector3d& centre, double radius_mm) {
  Grid3<float> grid(dims, 0.0f, frame_from_ijk);
  for (int k = 0; k < dims.z(); ++k) {
    for (int j = 0; j < dims.y(); ++j) {
      for (int i = 0; i < dims.x(); ++i) {
        const Eigen::Vector3d p = grid.PointFromIndex(Eigen::Vector3d(i, j, k));
        grid(i, j, k) = static_cast<float>((p - centre).norm() - radius_mm);
      }
    }
  }
  return grid;
}

Eigen::Matrix4d Affine(const Eigen::Matrix3d& linear, const Eigen::Vector3d& origin) {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.topLeftCorner<3, 3>() = linear;
  m.topRightCorner<3, 1>() = origin;
  return m;
}

/// Triangles whose normal points towards `centre` (inward for a sphere around it).
int CountInwardTriangles(const TriangleMesh& mesh, const Eigen::Vector3d& centre) {
  int inward = 0;
  for (const Eigen::Vector3i& t : mesh.triangles) {
    const Eigen::Vector3d& a = mesh.vertices[t[0]];
    const Eigen::Vector3d n = (mesh.vertices[t[1]] - a).cross(mesh.vertices[t[2]] - a);
    if (n.dot(a - centre) < 0.0) ++inward;
  }
  return inward;
}

double MaxSphereErrorMm(const TriangleMesh& mesh, const Eigen::Vector3d& centre, double radius) {
  double worst = 0.0;
  for (const Eigen::Vector3d& v : mesh.vertices) {
    worst = std::max(worst, std::abs((v - centre).norm() - radius));
  }
  return worst;
}

const Eigen::Vector3d kCentre(0.3, -0.2, 0.1);
constexpr double kRadiusMm = 20.0;

TEST(ExtractIsoSurfaceGrid, SphereAreaWithinOnePercentClosedAndOutward) {
  const Grid3<float> grid =
      SphereSdf(Eigen::Vector3i::Constant(48),
                Affine(Eigen::Matrix3d::Identity(), {-23.7, -24.1, -23.3}), kCentre, kRadiusMm);
  const TriangleMesh mesh = ExtractIsoSurface(grid);
  ASSERT_GT(mesh.triangles.size(), 1000u);
  const double area = 4.0 * std::numbers::pi * kRadiusMm * kRadiusMm;
  EXPECT_NEAR(mesh.SurfaceAreaMm2(), area, kAreaRelTol * area);
  const EdgeCounts edges = CountEdges(mesh);
  EXPECT_EQ(edges.boundary, 0);  // watertight: every edge in exactly two triangles
  EXPECT_EQ(edges.non_manifold, 0);
  EXPECT_EQ(edges.misoriented, 0);
  EXPECT_EQ(CountDuplicateVertices(mesh), 0);  // shared across tile borders too
  EXPECT_EQ(CountInwardTriangles(mesh, kCentre), 0);
  EXPECT_LT(MaxSphereErrorMm(mesh, kCentre, kRadiusMm), kSdfVertexTolMm);
}

TEST(ExtractIsoSurfaceGrid, AnisotropicRotatedAndMirroredFramesStayOutward) {
  const Eigen::Matrix3d rotation =
      Eigen::AngleAxisd(0.4, Eigen::Vector3d(1.0, 2.0, 0.5).normalized()).toRotationMatrix();
  const Eigen::Matrix3d spacing = Eigen::Vector3d(0.8, 1.1, 1.3).asDiagonal();
  const Eigen::Matrix3d mirror = Eigen::Vector3d(-1.0, 1.0, 1.0).asDiagonal();
  const Eigen::Vector3i dims(40, 30, 26);  // covers the 15 mm sphere at these spacings
  constexpr double kRadius = 15.0;
  const Eigen::Vector3d middle = 0.5 * (dims - Eigen::Vector3i::Ones()).cast<double>();
  for (const Eigen::Matrix3d& linear :
       {Eigen::Matrix3d(rotation * spacing), Eigen::Matrix3d(mirror * rotation * spacing)}) {
    const Eigen::Vector3d origin = kCentre - linear * middle;
    const TriangleMesh mesh =
        ExtractIsoSurface(SphereSdf(dims, Affine(linear, origin), kCentre, kRadius));
    const double area = 4.0 * std::numbers::pi * kRadius * kRadius;
    EXPECT_NEAR(mesh.SurfaceAreaMm2(), area, kAreaRelTol * area);
    EXPECT_EQ(CountInwardTriangles(mesh, kCentre), 0) << "det " << linear.determinant();
    EXPECT_EQ(CountEdges(mesh).boundary, 0);
  }
}

TEST(ExtractIsoSurfaceGrid, BelowOutsideAndIsoValue) {
  // A "CT" whose inside is brighter: negated distance, outside below the iso value. An iso value
  // of -5 (5 mm outside the 10 mm sphere) gives radius 15 mm.
  constexpr double kRadius = 10.0;
  Grid3<float> grid =
      SphereSdf(Eigen::Vector3i::Constant(36),
                Affine(Eigen::Matrix3d::Identity(), {-17.6, -17.4, -17.5}), kCentre, kRadius);
  for (float& v : grid.values()) v = -v;
  GridIsoSurfaceOptions options;
  options.iso_value = -5.0f;
  options.outside = IsoSurfaceOutside::kBelow;
  const TriangleMesh mesh = ExtractIsoSurface(grid, options);
  EXPECT_EQ(CountInwardTriangles(mesh, kCentre), 0);
  EXPECT_LT(MaxSphereErrorMm(mesh, kCentre, kRadius + 5.0), kSdfVertexTolMm);
  options.outside = IsoSurfaceOutside::kAbove;  // the same surface, facing inwards
  EXPECT_EQ(CountInwardTriangles(ExtractIsoSurface(grid, options), kCentre),
            static_cast<int>(mesh.triangles.size()));
}

TEST(ExtractIsoSurfaceGrid, RandomFieldGivesClosedConsistentlyOrientedSurface) {
  // Random values exercise every case, the ambiguous faces included: a positive border closes
  // the surface, so any crack or flipped triangle between cells shows as an edge count.
  const Eigen::Vector3i dims(21, 19, 23);
  Grid3<float> grid(dims, 1.0f, Affine(Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero()));
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<float> value(-1.0f, 1.0f);
  std::vector<int> case_seen(256, 0);
  for (int k = 1; k + 1 < dims.z(); ++k) {
    for (int j = 1; j + 1 < dims.y(); ++j) {
      for (int i = 1; i + 1 < dims.x(); ++i) grid(i, j, k) = value(rng);
    }
  }
  for (int k = 0; k + 1 < dims.z(); ++k) {
    for (int j = 0; j + 1 < dims.y(); ++j) {
      for (int i = 0; i + 1 < dims.x(); ++i) {
        int mask = 0;
        for (int c = 0; c < 8; ++c) {
          if (grid(i + (c & 1), j + ((c >> 1) & 1), k + ((c >> 2) & 1)) < 0.0f) mask |= 1 << c;
        }
        case_seen[static_cast<std::size_t>(mask)] = 1;
      }
    }
  }
  const TriangleMesh mesh = ExtractIsoSurface(grid);
  const EdgeCounts edges = CountEdges(mesh);
  EXPECT_GT(std::count(case_seen.begin(), case_seen.end(), 1), 250);
  EXPECT_EQ(edges.boundary, 0);
  EXPECT_EQ(edges.non_manifold, 0);
  EXPECT_EQ(edges.misoriented, 0);
  EXPECT_EQ(CountDuplicateVertices(mesh), 0);
}

TEST(ExtractIsoSurfaceGrid, MissingValuesLeaveAnOpenPatch) {
  Grid3<float> grid =
      SphereSdf(Eigen::Vector3i::Constant(48),
                Affine(Eigen::Matrix3d::Identity(), {-23.7, -24.1, -23.3}), kCentre, kRadiusMm);
  for (int k = 0; k < 48; ++k) {
    for (int j = 0; j < 48; ++j) {
      for (int i = 30; i < 48; ++i) grid(i, j, k) = std::numeric_limits<float>::quiet_NaN();
    }
  }
  const TriangleMesh mesh = ExtractIsoSurface(grid);
  EXPECT_GT(CountEdges(mesh).boundary, 0);
  for (const Eigen::Vector3d& v : mesh.vertices) EXPECT_LE(v.x(), -23.7 + 29.0);
}

TEST(ExtractIsoSurfaceGrid, SurfaceCutByTheLastLayerIsMeshedOpen) {
  // 25 samples = 24 cells = exactly three tiles per axis: the last layer's in-layer edges are
  // owned by a fourth tile (the real MR head ch2.nii.gz has 217 samples along y). A sphere
  // centred on the far corner crosses all three last layers; its octant is meshed, open there.
  constexpr int kSide = 3 * 8 + 1;
  const double last = kSide - 1;
  const Eigen::Vector3d corner = Eigen::Vector3d::Constant(last);
  // Not a whole number of 1 mm voxels: no sample lies exactly on the surface (a vertex there
  // would sit on a lattice point, repeated by every edge meeting it).
  constexpr double kRadius = 19.5;
  const Grid3<float> grid =
      SphereSdf(Eigen::Vector3i::Constant(kSide),
                Affine(Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero()), corner, kRadius);
  const TriangleMesh mesh = ExtractIsoSurface(grid);
  ASSERT_FALSE(mesh.triangles.empty());
  EXPECT_NEAR(mesh.SurfaceAreaMm2(), std::numbers::pi * kRadius * kRadius / 2.0,
              kAreaRelTol * std::numbers::pi * kRadius * kRadius / 2.0);  // 4 pi R^2 / 8
  EXPECT_LT(MaxSphereErrorMm(mesh, corner, kRadius), kSdfVertexTolMm);
  EXPECT_EQ(CountInwardTriangles(mesh, corner), 0);
  const EdgeCounts edges = CountEdges(mesh);
  EXPECT_EQ(edges.non_manifold, 0);
  EXPECT_EQ(edges.misoriented, 0);
  EXPECT_GT(edges.boundary, 0);
  EXPECT_EQ(CountDuplicateVertices(mesh), 0);
  // Open only where the border cuts it: both ends of every boundary edge lie on one last layer.
  std::map<std::pair<int, int>, int> uses;
  for (const Eigen::Vector3i& t : mesh.triangles) {
    for (int k = 0; k < 3; ++k) ++uses[std::minmax(t[k], t[(k + 1) % 3])];
  }
  for (const auto& [edge, count] : uses) {
    if (count != 1) continue;
    const Eigen::Vector3d &a = mesh.vertices[static_cast<std::size_t>(edge.first)],
                          &b = mesh.vertices[static_cast<std::size_t>(edge.second)];
    EXPECT_TRUE((a.array() == last && b.array() == last).any())
        << a.transpose() << " - " << b.transpose();
  }
}

TEST(MarchingCubesTables, TrianglesUseExactlyTheCrossedEdges) {
  for (int mask = 0; mask < 256; ++mask) {
    const McCase& c = MarchingCubesCase(mask);
    std::vector<int> used(12, 0);
    for (int k = 0; k < 3 * c.triangle_count; ++k) used[c.edges[static_cast<std::size_t>(k)]] = 1;
    for (int e = 0; e < 12; ++e) {
      const bool crossed =
          (((mask >> McEdgeLowerCorner(e)) ^ (mask >> McEdgeUpperCorner(e))) & 1) != 0;
      EXPECT_EQ(used[static_cast<std::size_t>(e)] == 1, crossed)
          << "mask " << mask << " edge " << e;
    }
  }
}

TEST(Grid3, LayoutTransformAndChecks) {
  Grid3<float> grid(Eigen::Vector3i(3, 4, 5), 0.0f,
                    Affine(Eigen::Vector3d(0.5, 1.0, 2.0).asDiagonal(), {10.0, 20.0, 30.0}));
  EXPECT_EQ(grid.size(), 60u);
  EXPECT_EQ(grid.Index(2, 1, 1), 2u + 3u * (1u + 4u * 1u));
  EXPECT_TRUE(grid.PointFromIndex({2.0, 1.0, 1.0}).isApprox(Eigen::Vector3d(11.0, 21.0, 32.0)));
  EXPECT_THROW(grid.At(3, 0, 0), PreconditionError);
  EXPECT_THROW(Grid3<float>(Eigen::Vector3i(2, 2, 2), std::vector<float>(7)), PreconditionError);
  EXPECT_THROW(Grid3<float>(Eigen::Vector3i(2, 2, 2), 0.0f, Eigen::Matrix4d::Zero()),
               PreconditionError);
  GridIsoSurfaceOptions options;
  options.iso_value = std::numeric_limits<float>::infinity();
  EXPECT_THROW(ExtractIsoSurface(grid, options), PreconditionError);
  EXPECT_TRUE(ExtractIsoSurface(Grid3<float>()).triangles.empty());
}

}  // namespace
}  // namespace tofnav
