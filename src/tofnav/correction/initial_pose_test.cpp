// SPDX-License-Identifier: BSD-3-Clause
// The skin's first placement: the head phantom seen from five rig poses, placed from two starts.
#include "tofnav/correction/initial_pose.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "correction_test_scenes.hpp"
#include "registration_scenes.hpp"

namespace tofnav {
namespace {

// Noise-free samples: the placement from the true model is exact up to the ICP's tolerance.
constexpr double kExactTranslationMm = 0.1;
constexpr double kExactRotationDeg = 0.05;

// A camera at `eye` (image frame) looking at the head's centre, +y of `ahat` roughly down.
Rigid3d ImageFromAhat(const Eigen::Vector3d& eye) {
  const Eigen::Vector3d z = (Eigen::Vector3d(0.0, 0.0, 20.0) - eye).normalized();
  const Eigen::Vector3d x = z.cross(Eigen::Vector3d::UnitZ()).normalized();
  Eigen::Matrix3d r;
  r << x, z.cross(x), z;
  return Rigid3d(Eigen::Quaterniond(r), eye);
}

// The phantom's skin seen from `image_from_ahat`: vertices facing the camera (theta < 60 deg)
// on the face and forehead, measured with `model`; the rig pose is image_from_ahat (world =
// image).
IdentificationFrame View(int index, const TriangleMesh& skin, const Points3d& normals,
                         const Rigid3d& image_from_ahat, const DepthErrorModel& model) {
  IdentificationFrame frame;
  frame.index = index;
  const Rigid3d ahat_from_image = image_from_ahat.Inverse();
  for (std::size_t v = 0; v < skin.vertices.size(); ++v) {
    if (!test::IsFrontal(skin.vertices[v], normals[v])) continue;
    const Eigen::Vector3d p = ahat_from_image * skin.vertices[v];
    const Eigen::Vector3d ray = p.normalized();
    const double cosine = -ray.dot(ahat_from_image.rotation * normals[v]);
    if (cosine < 0.5) continue;
    const double d = p.norm(), theta = std::acos(cosine);
    frame.head.push_back({ray.cast<float>(), static_cast<float>(d + model.BiasMm(d, theta)),
                          static_cast<float>(theta), 130.0f});
  }
  frame.world_from_ahat = image_from_ahat;
  return frame;
}

struct Scene {
  TriangleMesh skin = test::PhantomSkin();
  std::vector<Rigid3d> image_from_ahat;
  std::vector<IdentificationFrame> frames;
};

// Five views from in front of the face, 450-600 mm away, 35 deg apart at most.
Scene FiveViews(const DepthErrorModel& truth) {
  Scene scene;
  const Points3d normals = scene.skin.ComputeVertexNormals();
  for (int k = 0; k < 5; ++k) {
    const double azimuth = (k - 2) * 0.3, distance = 450.0 + 35.0 * k;
    const Eigen::Vector3d eye(distance * std::sin(azimuth), distance * std::cos(azimuth),
                              60.0 + 20.0 * (k % 2));
    scene.image_from_ahat.push_back(ImageFromAhat(eye));
    scene.frames.push_back(View(k, scene.skin, normals, scene.image_from_ahat.back(), truth));
  }
  return scene;
}

// Where the headframe is, rigid with the head.
const Rigid3d kToolFromImage(Eigen::Quaterniond(Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitX())),
                             Eigen::Vector3d(10.0, 80.0, 120.0));

TEST(InitialImageFromBestStart, KeepsThePlacementOfTheStartThatPutsMoreOfTheHeadOnTheSkin) {
  const DepthErrorModel truth = testing::TrueModel();
  // 10 mm too little correction head-on, 18 mm at 60 deg: the views disagree (measured: 66 %
  // of the merged cloud within the finest gate, against 99 % for the true model).
  DepthErrorModel wrong = truth;
  wrong.c1_mm -= 10.0;
  wrong.c3_mm -= 8.0;
  const Scene scene = FiveViews(truth);
  const SurfaceIndex skin(scene.skin);
  for (const bool true_first : {true, false}) {
    const std::array<DepthErrorModel, 2> starts =
        true_first ? std::array{truth, wrong} : std::array{wrong, truth};
    const BestStartPlacement best = InitialImageFromBestStart(scene.frames, skin, starts);
    ASSERT_EQ(best.start, true_first ? 0 : 1);
    // The rule's figure: the other start keeps less of the cloud within the finest gate.
    const InitialPoseResult other = InitialImageFromAhat(scene.frames, skin, wrong);
    EXPECT_GT(best.pose.registration.icp.inlier_fraction,
              other.registration.icp.inlier_fraction + 0.05);
    for (std::size_t i = 0; i < scene.frames.size(); ++i) {
      ASSERT_TRUE(best.pose.image_from_ahat[i].has_value());
      const Rigid3d error = scene.image_from_ahat[i].Inverse() * *best.pose.image_from_ahat[i];
      EXPECT_LT(error.translation.norm(), kExactTranslationMm) << "frame " << i;
      EXPECT_LT(Eigen::AngleAxisd(error.rotation).angle() * 180.0 / std::numbers::pi,
                kExactRotationDeg)
          << "frame " << i;
    }
  }
}

// The patient drifts 3 mm between views along an oblique direction (the suite's drift cases:
// 1 mm/s over a 13 s recording); the headframe moves with the head.
TEST(InitialImageFromAhat, MergesThroughTheReferenceToolWhileThePatientMoves) {
  const DepthErrorModel truth = testing::TrueModel();
  Scene scene = FiveViews(truth);
  const Rigid3d tool_from_image = kToolFromImage;
  const Eigen::Vector3d drift_direction = Eigen::Vector3d(1.0, -0.5, 0.7).normalized();
  for (std::size_t k = 0; k < scene.frames.size(); ++k) {
    const Rigid3d world_from_image(Eigen::Quaterniond::Identity(),
                                   3.0 * static_cast<double>(k) * drift_direction);
    scene.frames[k].world_from_ahat = world_from_image * scene.image_from_ahat[k];
    scene.frames[k].tool_from_ahat = tool_from_image * scene.image_from_ahat[k];
  }
  const SurfaceIndex skin(scene.skin);
  const InitialPoseResult placed = InitialImageFromAhat(scene.frames, skin, truth);
  EXPECT_TRUE(placed.through_tool);
  for (std::size_t i = 0; i < scene.frames.size(); ++i) {
    ASSERT_TRUE(placed.image_from_ahat[i].has_value());
    const Rigid3d error = scene.image_from_ahat[i].Inverse() * *placed.image_from_ahat[i];
    EXPECT_LT(error.translation.norm(), kExactTranslationMm) << "frame " << i;
    EXPECT_LT(Eigen::AngleAxisd(error.rotation).angle() * 180.0 / std::numbers::pi,
              kExactRotationDeg)
        << "frame " << i;
  }
  // Through `world` (no tool poses) the same frames are 12 mm apart at the ends: some frame's
  // placement is off by millimetres, which is what the tool avoids.
  for (IdentificationFrame& f : scene.frames) f.tool_from_ahat.reset();
  const InitialPoseResult smeared = InitialImageFromAhat(scene.frames, skin, truth);
  EXPECT_FALSE(smeared.through_tool);
  double worst_mm = 0.0;
  for (std::size_t i = 0; i < scene.frames.size(); ++i) {
    const Rigid3d error = scene.image_from_ahat[i].Inverse() * *smeared.image_from_ahat[i];
    worst_mm = std::max(worst_mm, error.translation.norm());
  }
  EXPECT_GT(worst_mm, 3.0);
}

// Another run's placement, a few millimetres and degrees off, is refined by the ICP from where it
// is (no coarse search) to the exact placement, and competes with the starts' placements.
TEST(InitialImageFromAhat, RefinesAnotherRunsPlacementThroughTheTool) {
  const DepthErrorModel truth = testing::TrueModel();
  Scene scene = FiveViews(truth);
  const Rigid3d tool_from_image = kToolFromImage;
  for (std::size_t k = 0; k < scene.frames.size(); ++k)
    scene.frames[k].tool_from_ahat = tool_from_image * scene.image_from_ahat[k];
  const Rigid3d off(
      Eigen::Quaterniond(Eigen::AngleAxisd(0.03, Eigen::Vector3d(1, 1, 0).normalized())),
      Eigen::Vector3d(2.0, -1.5, 1.0));
  const MergedPlacement guess{off * tool_from_image.Inverse(), true};
  const SurfaceIndex skin(scene.skin);
  const InitialPoseResult placed = InitialImageFromAhat(scene.frames, skin, truth, {}, guess);
  EXPECT_EQ(placed.registration.coarse.hypotheses, 0);  // started from the guess
  ASSERT_TRUE(placed.through_tool);
  const Rigid3d error = tool_from_image * placed.image_from_merged;
  EXPECT_LT(error.translation.norm(), kExactTranslationMm);
  EXPECT_LT(Eigen::AngleAxisd(error.rotation).angle() * 180.0 / std::numbers::pi,
            kExactRotationDeg);
  EXPECT_FALSE(PlacementsDiffer({placed.image_from_merged, placed.through_tool},
                                {tool_from_image.Inverse(), true}));
  EXPECT_TRUE(PlacementsDiffer(guess, {tool_from_image.Inverse(), true}, 0.01, 5.0));
  // Beside the start's own placement it scores the same: both end exact.
  const std::array<DepthErrorModel, 1> starts{truth};
  const std::array<MergedPlacement, 1> guesses{guess};
  const BestStartPlacement best =
      InitialImageFromBestStart(scene.frames, skin, starts, {}, guesses);
  ASSERT_EQ(best.inlier_fractions.size(), 2u);
  EXPECT_NEAR(best.inlier_fractions[1], best.inlier_fractions[0], 0.01);
}

TEST(PlacementsDiffer, AnotherBasinIsBeyondTheTolerances) {
  const MergedPlacement a{Rigid3d(Eigen::Quaterniond::Identity(), Eigen::Vector3d(5, 0, 0)), true};
  MergedPlacement b = a;
  b.image_from_merged.translation.x() += 4.0;
  EXPECT_FALSE(PlacementsDiffer(a, b));  // 4 mm: within 5
  b.image_from_merged.translation.x() += 2.0;
  EXPECT_TRUE(PlacementsDiffer(a, b));  // 6 mm
  b = a;
  b.image_from_merged.rotation = Eigen::AngleAxisd(0.06, Eigen::Vector3d::UnitZ());
  EXPECT_TRUE(PlacementsDiffer(a, b));  // 0.06 rad against 0.05
  b.through_tool = false;
  EXPECT_FALSE(PlacementsDiffer(a, b));  // through `world`: no comparison
}

TEST(InitialImageFromBestStart, ThrowsWithoutAStart) {
  const Scene scene = FiveViews(testing::TrueModel());
  EXPECT_THROW(InitialImageFromBestStart(scene.frames, SurfaceIndex(scene.skin), {}),
               std::invalid_argument);
}

}  // namespace
}  // namespace tofnav
