// SPDX-License-Identifier: BSD-3-Clause
// SurfaceIndex against brute force; PCA normals on a sphere; mesh normals; spacing.
#include "tofnav/registration/surface_index.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

#include "tofnav/sim/shapes.hpp"

namespace tofnav {
namespace {

// PCA over 16 neighbours (about 10 deg of arc); the lattice is slightly uneven at its poles.
constexpr double kNormalTolRad = 1.5 * std::numbers::pi / 180.0;

PointCloud RandomCloud(std::size_t count, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-50.0, 50.0);
  PointCloud cloud;
  for (std::size_t i = 0; i < count; ++i) {
    cloud.points.emplace_back(u(rng), u(rng), u(rng));
    cloud.normals.push_back(Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized());
  }
  return cloud;
}

std::vector<double> BruteDistancesSq(const Points3d& points, const Eigen::Vector3d& query) {
  std::vector<double> d;
  for (const Eigen::Vector3d& p : points) d.push_back((p - query).squaredNorm());
  return d;
}

TEST(SurfaceIndex, NearestAndNearestKMatchBruteForceWithinTheBound) {
  const PointCloud cloud = RandomCloud(500, 1);
  const SurfaceIndex index(cloud);
  std::mt19937_64 rng(2);
  std::uniform_real_distribution<double> u(-60.0, 60.0);
  int found = 0, missed = 0;
  for (int q = 0; q < 200; ++q) {
    const Eigen::Vector3d query(u(rng), u(rng), u(rng));
    const std::vector<double> d = BruteDistancesSq(cloud.points, query);
    const auto best = std::min_element(d.begin(), d.end());
    const std::optional<Neighbour> near = index.Nearest(query, 6.0);
    // NearestK: the k nearest within the bound in order, the first being Nearest's, and the
    // (k + 1)-th nearest (or the bound) for the others.
    std::vector<double> sorted = d;
    std::sort(sorted.begin(), sorted.end());
    for (const int k : {1, 4, SurfaceIndex::kMaxNearestSet}) {
      const SurfaceIndex::NearestSet set = index.NearestK(query, k, 6.0);
      const auto within = std::lower_bound(sorted.begin(), sorted.end(), 36.0) - sorted.begin();
      ASSERT_EQ(set.count, std::min<int>(k, static_cast<int>(within)));
      for (int i = 0; i < set.count; ++i) {
        EXPECT_EQ(set.nearest[static_cast<std::size_t>(i)].distance_sq_mm2,
                  sorted[static_cast<std::size_t>(i)]);
        EXPECT_EQ(d[set.nearest[static_cast<std::size_t>(i)].index],
                  sorted[static_cast<std::size_t>(i)]);
      }
      EXPECT_DOUBLE_EQ(set.others_from_mm,
                       std::min(std::sqrt(sorted[static_cast<std::size_t>(k)]), 6.0));
      EXPECT_EQ(set.count > 0, near.has_value());
      if (near) {
        EXPECT_EQ(set.nearest[0].index, near->index);
      }
    }
    if (*best < 36.0) {
      ASSERT_TRUE(near.has_value());
      EXPECT_EQ(near->index, static_cast<std::uint32_t>(best - d.begin()));
      EXPECT_DOUBLE_EQ(near->distance_sq_mm2, *best);
      ++found;
    } else {
      EXPECT_FALSE(near.has_value());
      ++missed;
    }
  }
  EXPECT_GT(found, 10);  // both branches exercised
  EXPECT_GT(missed, 10);
}

TEST(SurfaceIndex, KNearestAndWithinRadiusMatchBruteForce) {
  const PointCloud cloud = RandomCloud(300, 3);
  const SurfaceIndex index(cloud);
  const Eigen::Vector3d query(1.0, -2.0, 3.0);
  std::vector<double> d = BruteDistancesSq(cloud.points, query);
  std::sort(d.begin(), d.end());
  const std::vector<Neighbour> k = index.KNearest(query, 7);
  ASSERT_EQ(k.size(), 7u);
  for (std::size_t i = 0; i < k.size(); ++i) EXPECT_DOUBLE_EQ(k[i].distance_sq_mm2, d[i]);
  const std::vector<Neighbour> r = index.WithinRadius(query, 20.0);
  EXPECT_EQ(r.size(), static_cast<std::size_t>(
                          std::count_if(d.begin(), d.end(), [](double v) { return v < 400.0; })));
  EXPECT_TRUE(std::is_sorted(r.begin(), r.end(), [](const Neighbour& a, const Neighbour& b) {
    return a.distance_sq_mm2 < b.distance_sq_mm2;
  }));
  EXPECT_EQ(index.KNearest(query, 1000).size(), cloud.points.size());
}

/// Evenly spread points on a sphere of radius 60 mm (Fibonacci lattice: no pole clusters).
Points3d FibonacciSphere(int count) {
  Points3d points;
  const double golden = std::numbers::pi * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < count; ++i) {
    const double z = 1.0 - 2.0 * (i + 0.5) / count, r = std::sqrt(1.0 - z * z);
    points.push_back(60.0 * Eigen::Vector3d(r * std::cos(golden * i), r * std::sin(golden * i), z));
  }
  return points;
}

TEST(SurfaceIndex, EstimatesOutwardNormalsByPca) {
  const Points3d sphere = FibonacciSphere(2000);
  const SurfaceIndex outward(sphere, {});
  for (std::size_t i = 0; i < outward.size(); ++i) {
    const Eigen::Vector3d radial = outward.points()[i].normalized();
    EXPECT_LT(std::acos(std::min(1.0, outward.normals()[i].dot(radial))), kNormalTolRad) << i;
  }
  SurfaceIndexOptions towards_centre;
  towards_centre.viewpoint = Eigen::Vector3d::Zero();
  const SurfaceIndex inward(sphere, {}, towards_centre);
  EXPECT_LT(inward.normals()[10].dot(inward.points()[10].normalized()), -0.99);
}

TEST(SurfaceIndex, MeshWithoutNormalsUsesItsTrianglesAndDropsLooseVertices) {
  TriangleMesh mesh = sim::SphereMesh(40.0, 24);
  mesh.vertex_normals.clear();
  mesh.vertices.emplace_back(500.0, 0.0, 0.0);  // used by no triangle: zero normal
  const SurfaceIndex index(mesh);
  EXPECT_EQ(index.size(), mesh.vertices.size() - 1);
  EXPECT_GT(index.normals().front().dot(index.points().front().normalized()), 0.99);
}

TEST(SurfaceIndex, SpacingIsTheGridPitch) {
  PointCloud grid;
  for (int x = 0; x < 30; ++x) {
    for (int y = 0; y < 30; ++y) {
      grid.points.emplace_back(2.5 * x, 2.5 * y, 0.0);
      grid.normals.emplace_back(0.0, 0.0, 1.0);
    }
  }
  EXPECT_DOUBLE_EQ(SurfaceIndex(grid).spacing_mm(), 2.5);
}

TEST(SurfaceIndex, RejectsTooFewPointsAndBadOptions) {
  PointCloud two;
  two.points = {{0, 0, 0}, {1, 0, 0}};
  EXPECT_THROW(SurfaceIndex{two}, std::invalid_argument);
  PointCloud mismatched = RandomCloud(10, 4);
  mismatched.normals.pop_back();
  EXPECT_THROW(SurfaceIndex{mismatched}, std::invalid_argument);
  SurfaceIndexOptions options;
  options.normal_neighbours = 2;
  EXPECT_THROW(options.Check(), std::invalid_argument);
}

}  // namespace
}  // namespace tofnav
