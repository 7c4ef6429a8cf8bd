// SPDX-License-Identifier: BSD-3-Clause
// RegisterSurface on the head phantom: automatic recovery, TRE at deep targets, refusals.
#include "tofnav/registration/register_surface.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <random>

#include "matchers.hpp"
#include "registration_scenes.hpp"
#include "tofnav/sim/head_phantom.hpp"
#include "tofnav/sim/shapes.hpp"

namespace tofnav {
namespace {

constexpr double kExactRotRad = 0.05 * std::numbers::pi / 180.0;  // acceptance: noise-free
constexpr double kExactTransMm = 0.05;
constexpr double kMaxTreMm = 1.0;  // acceptance: deep targets, 0.3 mm reconstruction noise
constexpr double kNoiseMm = 0.3;   // reconstruction error of the acceptance test
constexpr double kStartAngleRad = 30.0 * std::numbers::pi / 180.0;  // acceptance start range
constexpr double kStartShiftMm = 50.0;

/// A partial reconstruction: the frontal skin seen in the tool frame.
PointCloud Reconstruction(const TriangleMesh& skin, const Rigid3d& tool_from_image, double noise_mm,
                          std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  const PointCloud in_image = noise_mm > 0.0 ? test::FrontalSamples(skin, 1500, noise_mm, rng)
                                             : test::FrontalVertices(skin);
  return Transform(tool_from_image, in_image);
}

double MaxTreMm(const Rigid3d& estimate, const Rigid3d& truth) {
  double worst = 0.0;
  for (const Eigen::Vector3d& target : test::DeepTargets()) {
    worst = std::max(worst, (estimate * target - truth * target).norm());
  }
  return worst;
}

class RegisterSurfaceSeeds : public testing::TestWithParam<std::uint64_t> {};

TEST_P(RegisterSurfaceSeeds, RecoversNoiseFreePoseFromRandomStart) {
  const TriangleMesh skin = test::PhantomSkin();
  const SurfaceIndex skin_in_image(skin);
  std::mt19937_64 rng(GetParam());
  const Rigid3d tool_from_image = test::RandomRigid(rng, kStartAngleRad, kStartShiftMm);
  const RegisterSurfaceResult r =
      RegisterSurface(Reconstruction(skin, tool_from_image, 0.0, GetParam()), skin_in_image,
                      test::DeepTargets(), test::FastTestOptions());
  EXPECT_TRUE(r.quality.accepted()) << r.quality.message;
  EXPECT_THAT(r.tool_from_image, RigidNear(tool_from_image, kExactRotRad, kExactTransMm));
}

TEST_P(RegisterSurfaceSeeds, DeepTargetErrorWithNoisyReconstruction) {
  const TriangleMesh skin = test::PhantomSkin();
  const SurfaceIndex skin_in_image(skin);
  std::mt19937_64 rng(GetParam() + 100);
  const Rigid3d tool_from_image = test::RandomRigid(rng, kStartAngleRad, kStartShiftMm);
  const RegisterSurfaceResult r =
      RegisterSurface(Reconstruction(skin, tool_from_image, kNoiseMm, GetParam()), skin_in_image,
                      test::DeepTargets(), test::FastTestOptions());
  EXPECT_TRUE(r.quality.accepted()) << r.quality.message;
  EXPECT_LE(MaxTreMm(r.tool_from_image, tool_from_image), kMaxTreMm);
  EXPECT_NEAR(r.quality.residual_sigma_mm, kNoiseMm, 0.1) << "noise level not recovered";
  ASSERT_EQ(r.quality.predicted_tre_mm.size(), test::DeepTargets().size());
  EXPECT_LT(r.quality.max_predicted_tre_mm, kMaxTreMm);
}

INSTANTIATE_TEST_SUITE_P(Seeds, RegisterSurfaceSeeds, testing::Values(1, 2, 3));

TEST(RegisterSurface, AnyOrientation) {
  const TriangleMesh skin = test::PhantomSkin();
  const SurfaceIndex skin_in_image(skin);
  const Rigid3d tool_from_image(
      Eigen::Quaterniond(Eigen::AngleAxisd(2.6, Eigen::Vector3d(1, -2, 0.5).normalized())),
      Eigen::Vector3d(-40.0, 120.0, 380.0));
  const RegisterSurfaceResult r = RegisterSurface(Reconstruction(skin, tool_from_image, 0.0, 9),
                                                  skin_in_image, {}, test::FastTestOptions());
  EXPECT_TRUE(r.quality.accepted()) << r.quality.message;
  EXPECT_THAT(r.tool_from_image, RigidNear(tool_from_image, kExactRotRad, kExactTransMm));
}

TEST(RegisterSurface, RefusesPlaneThatIsNotOnTheSkin) {
  const SurfaceIndex skin_in_image(test::PhantomSkin());
  PointCloud cloud;
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<double> u(-60.0, 60.0);
  for (int i = 0; i < 800; ++i) {
    cloud.points.emplace_back(u(rng), u(rng), 600.0);
    cloud.normals.emplace_back(0.0, 0.0, 1.0);
  }
  const RegisterSurfaceResult r =
      RegisterSurface(cloud, skin_in_image, test::DeepTargets(), test::FastTestOptions());
  EXPECT_FALSE(r.quality.accepted());
  EXPECT_FALSE(r.quality.message.empty());
}

TEST(RegisterSurface, RefusesSphereAsIllConditioned) {
  const TriangleMesh sphere = sim::SphereMesh(90.0, 96);
  const SurfaceIndex sphere_in_image(sphere);
  PointCloud cap;
  for (std::size_t i = 0; i < sphere.vertices.size(); ++i) {
    if (sphere.vertex_normals[i].y() < 0.5) continue;
    cap.points.push_back(sphere.vertices[i] + Eigen::Vector3d(10, 20, 30));
    cap.normals.push_back(sphere.vertex_normals[i]);
  }
  const RegisterSurfaceResult r =
      RegisterSurface(cap, sphere_in_image, test::DeepTargets(), test::FastTestOptions());
  EXPECT_EQ(r.quality.status, RegistrationStatus::kIllConditioned) << r.quality.message;
  EXPECT_LT(r.quality.conditioning.rotation, RegistrationThresholds().min_rotation_conditioning);
}

TEST(RegisterSurface, RefusesFeaturelessEllipsoid) {
  // Without nose, brow and eyes the head is an ellipsoid: the frontal patch turns about the
  // front-back axis almost freely, and turned by 180 deg it fits the skin as well.
  sim::HeadPhantomOptions options;
  options.segments = 96;
  options.nose_height_mm = options.brow_height_mm = options.eye_socket_depth_mm = 0.0;
  const TriangleMesh ellipsoid = sim::HeadPhantomMesh(options);
  const Rigid3d tool_from_image(
      Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitX())),
      Eigen::Vector3d(10.0, 20.0, 350.0));
  const RegisterSurfaceResult r =
      RegisterSurface(Reconstruction(ellipsoid, tool_from_image, 0.0, 6), SurfaceIndex(ellipsoid),
                      test::DeepTargets(), test::FastTestOptions());
  EXPECT_THAT(r.quality.status,
              testing::AnyOf(RegistrationStatus::kIllConditioned, RegistrationStatus::kAmbiguous))
      << r.quality.message;
  // The turned pose fits nearly as well (0.59 measured; a featured phantom head reads 0.52 with
  // a true TRE of 0.47 mm, docs/registration.md): ambiguity alone no longer refuses it, the
  // conditioning does.
  EXPECT_GT(r.quality.ambiguity, 0.5);
}

TEST(RegisterSurface, GuessSkipsCoarseAndFarGuessIsNoOverlap) {
  const TriangleMesh skin = test::PhantomSkin();
  const SurfaceIndex skin_in_image(skin);
  const Rigid3d tool_from_image(
      Eigen::Quaterniond(Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitZ())),
      Eigen::Vector3d(5.0, -3.0, 300.0));
  const PointCloud cloud = Reconstruction(skin, tool_from_image, 0.0, 5);
  const Rigid3d near_guess =
      Rigid3d(Eigen::Quaterniond::Identity(), Eigen::Vector3d(2.0, 1.0, -2.0)) * tool_from_image;
  const RegisterSurfaceResult good = RegisterSurface(cloud, skin_in_image, {}, {}, near_guess);
  EXPECT_EQ(good.coarse.hypotheses, 0);
  EXPECT_TRUE(good.quality.accepted()) << good.quality.message;
  EXPECT_THAT(good.tool_from_image, RigidNear(tool_from_image, kExactRotRad, kExactTransMm));
  const Rigid3d far_guess =
      Rigid3d(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0, 0, 500.0)) * tool_from_image;
  const RegisterSurfaceResult far = RegisterSurface(cloud, skin_in_image, {}, {}, far_guess);
  EXPECT_EQ(far.quality.status, RegistrationStatus::kNoOverlap) << far.quality.message;
}

TEST(RegisterSurfaceOptions, CheckNamesTheField) {
  RegisterSurfaceOptions options;
  options.thresholds.min_inlier_fraction = 1.5;
  EXPECT_THROW(options.Check(), std::invalid_argument);
  options = {};
  options.coarse.roll_steps = 0;
  EXPECT_THROW(options.Check(), std::invalid_argument);
}

}  // namespace
}  // namespace tofnav
