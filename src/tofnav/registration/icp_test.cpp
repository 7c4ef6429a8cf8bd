// SPDX-License-Identifier: BSD-3-Clause
// Point-to-plane ICP on the head phantom: recovery, determinism, robustness, gating, sliding.
#include "tofnav/registration/icp.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <numbers>
#include <random>

#include "matchers.hpp"
#include "registration_scenes.hpp"
#include "tofnav/sim/shapes.hpp"

namespace tofnav {
namespace {

constexpr double kRotTolRad = 0.05 * std::numbers::pi / 180.0;  // noise-free: near-exact
constexpr double kTransTolMm = 0.05;

struct FaceScene {
  TriangleMesh skin = test::PhantomSkin();
  SurfaceIndex skin_in_image{skin};
  PointCloud face_in_image = test::FrontalVertices(skin);
  /// The guess: 5 deg and 8 mm from the identity truth (within the ICP basin).
  Rigid3d guess{
      Eigen::Quaterniond(Eigen::AngleAxisd(0.087, Eigen::Vector3d(1, 2, -1).normalized())),
      Eigen::Vector3d(6.0, -4.0, 3.0)};
};

TEST(AlignPointToPlane, RecoversPoseOfSimulatedSkin) {
  const FaceScene scene;
  const IcpResult r = AlignPointToPlane(scene.face_in_image.points, scene.face_in_image.normals,
                                        scene.skin_in_image, scene.guess);
  ASSERT_TRUE(r.converged);
  EXPECT_THAT(r.target_from_source, RigidNear(Rigid3d::Identity(), kRotTolRad, kTransTolMm));
  EXPECT_DOUBLE_EQ(r.inlier_fraction, 1.0);
  EXPECT_LT(r.rmse_mm, 1e-6);
  EXPECT_GT(r.conditioning.rotation, 0.005);  // the face pins the rotation (default threshold)
  EXPECT_FALSE(r.history.empty());
  // The finest gate, raised to the phantom's coarse vertex spacing.
  EXPECT_EQ(r.history.back().max_distance_mm, std::max(IcpOptions().max_distance_schedule_mm.back(),
                                                       scene.skin_in_image.spacing_mm()));
}

TEST(AlignPointToPlane, SameResultForAnyThreadCount) {
  const FaceScene scene;
  std::mt19937_64 rng(3);
  const PointCloud noisy = test::FrontalSamples(scene.skin, 3000, 0.3, rng);  // > 1 chunk
  const auto run = [&] {
    return AlignPointToPlane(noisy.points, noisy.normals, scene.skin_in_image, scene.guess);
  };
  const IcpResult parallel = run();
  const tbb::global_control one_thread(tbb::global_control::max_allowed_parallelism, 1);
  const IcpResult serial = run();
  EXPECT_EQ(serial.iterations, parallel.iterations);
  EXPECT_EQ(serial.target_from_source.translation, parallel.target_from_source.translation);
  EXPECT_EQ(serial.target_from_source.rotation.coeffs(),
            parallel.target_from_source.rotation.coeffs());
  EXPECT_EQ(serial.information, parallel.information);
}

// The cache carries answers from one call to the next (an identification's evaluations move the
// same samples a little): every figure must be bit for bit that of a call without it, and its
// known nearest points must be the KD-tree's.
TEST(AlignPointToPlane, NeighbourCacheChangesNoFigure) {
  const FaceScene scene;
  std::mt19937_64 rng(5);
  PointCloud cloud = test::FrontalSamples(scene.skin, 3000, 0.3, rng);
  IcpNeighbourCache cache;
  std::normal_distribution<double> nudge(0.0, 0.05);  // mm: as a depth model's small change
  int known = 0;
  for (int call = 0; call < 4; ++call) {
    const IcpResult plain =
        AlignPointToPlane(cloud.points, cloud.normals, scene.skin_in_image, scene.guess);
    const IcpResult cached = AlignPointToPlane(cloud.points, cloud.normals, scene.skin_in_image,
                                               scene.guess, IcpOptions(), &cache);
    EXPECT_EQ(cached.iterations, plain.iterations) << call;
    EXPECT_EQ(cached.target_from_source.translation, plain.target_from_source.translation);
    EXPECT_EQ(cached.target_from_source.rotation.coeffs(),
              plain.target_from_source.rotation.coeffs());
    EXPECT_EQ(cached.inlier_indices, plain.inlier_indices);
    EXPECT_EQ(cached.information, plain.information);
    for (std::size_t i = 0; i < cloud.points.size(); ++i) {
      const Eigen::Vector3d p = cached.target_from_source * cloud.points[i];
      const std::optional<std::uint32_t> nearest = cache.KnownNearest(i, p);
      if (!nearest) continue;
      const std::optional<Neighbour> truth = scene.skin_in_image.Nearest(p, 1e3);
      ASSERT_TRUE(truth.has_value());
      EXPECT_EQ(*nearest, truth->index) << call << " " << i;
      ++known;
    }
    for (Eigen::Vector3d& p : cloud.points)
      p += Eigen::Vector3d(nudge(rng), nudge(rng), nudge(rng));
  }
  EXPECT_GT(known, 4000);  // the final pose's answers mostly still hold
}

TEST(AlignPointToPlane, RobustLossIgnoresOneSidedOutliers) {
  const FaceScene scene;
  PointCloud face = scene.face_in_image;
  for (std::size_t i = 0; i < face.points.size(); i += 4) face.points[i] += 1.8 * face.normals[i];
  IcpOptions options;
  options.loss = RobustLoss::kTukey;
  const IcpResult tukey =
      AlignPointToPlane(face.points, face.normals, scene.skin_in_image, scene.guess, options);
  EXPECT_THAT(tukey.target_from_source,
              RigidNear(Rigid3d::Identity(), 2 * kRotTolRad, 2 * kTransTolMm));
  options.loss = RobustLoss::kSquared;
  const IcpResult squared =
      AlignPointToPlane(face.points, face.normals, scene.skin_in_image, scene.guess, options);
  // Least squares is pulled towards the outliers (a quarter of the points 1.8 mm out).
  EXPECT_GT(TranslationDistanceMm(squared.target_from_source, Rigid3d::Identity()), 0.2);
}

TEST(AlignPointToPlane, NormalGateRejectsBackFaces) {
  const FaceScene scene;
  Points3d flipped = scene.face_in_image.normals;
  for (Eigen::Vector3d& n : flipped) n = -n;
  const IcpResult r =
      AlignPointToPlane(scene.face_in_image.points, flipped, scene.skin_in_image, scene.guess);
  EXPECT_FALSE(r.converged);
  EXPECT_EQ(r.correspondences, 0);
  EXPECT_EQ(r.inlier_fraction, 0.0);
}

TEST(AlignPointToPlane, GivesUpWithoutOverlap) {
  const FaceScene scene;
  const Rigid3d far(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0.0, 0.0, 400.0));
  const IcpResult r = AlignPointToPlane(scene.face_in_image.points, scene.face_in_image.normals,
                                        scene.skin_in_image, far);
  EXPECT_FALSE(r.converged);
  EXPECT_EQ(r.correspondences, 0);
  EXPECT_THAT(r.target_from_source, RigidNear(far, 0.0, 0.0));  // no step without data
}

TEST(AlignPointToPlane, SphereFixesItsCentreButNotItsRotation) {
  const TriangleMesh sphere = sim::SphereMesh(80.0, 64);
  const SurfaceIndex target(sphere);
  PointCloud cap;
  for (std::size_t i = 0; i < sphere.vertices.size(); ++i) {
    if (sphere.vertex_normals[i].z() < 0.6) continue;
    cap.points.push_back(sphere.vertices[i]);
    cap.normals.push_back(sphere.vertex_normals[i]);
  }
  const Rigid3d guess(Eigen::Quaterniond(Eigen::AngleAxisd(0.05, Eigen::Vector3d::UnitX())),
                      Eigen::Vector3d(2.0, -3.0, 1.0));
  const IcpResult r = AlignPointToPlane(cap.points, cap.normals, target, guess);
  // Any turn about the centre fits (up to the facets of the 64-segment mesh): far below the
  // face's 0.027 and the default refusal threshold of 0.005.
  EXPECT_LT(r.conditioning.rotation, 1e-3);
  EXPECT_LT(r.conditioning.overall, 1e-3);
  EXPECT_LT((r.target_from_source * Eigen::Vector3d::Zero()).norm(), kTransTolMm);  // centre
}

TEST(ComputeConditioning, PlaneLeavesTranslationAndTurnFree) {
  // 100 points of the plane z = 0 with normal +z, centred on their centroid.
  Matrix6d information = Matrix6d::Zero();
  for (int i = -5; i < 5; ++i) {
    for (int j = -5; j < 5; ++j) {
      const Eigen::Vector3d point(i + 0.5, j + 0.5, 0.0);
      Vector6d row;
      row << point.cross(Eigen::Vector3d::UnitZ()), Eigen::Vector3d::UnitZ();
      information += row * row.transpose();
    }
  }
  const PoseConditioning c = ComputeConditioning(information, 100, 100.0);
  EXPECT_NEAR(c.translation, 0.0, 1e-12);
  EXPECT_NEAR(c.rotation, 0.0, 1e-12);       // the turn about z
  EXPECT_NEAR(c.eigenvalues(5), 1.0, 1e-9);  // translation along z: 1 mm moves every point 1 mm
}

TEST(IcpOptions, CheckNamesTheField) {
  IcpOptions options;
  options.max_distance_schedule_mm.clear();
  EXPECT_THROW(options.Check(), std::invalid_argument);
  options = {};
  options.min_correspondences = 3;
  EXPECT_THROW(options.Check(), std::invalid_argument);
}

}  // namespace
}  // namespace tofnav
