// SPDX-License-Identifier: BSD-3-Clause
// Eq. (5) through the reference tool: an ellipsoid head seen from several directions.
#include "tofnav/correction/joint_correctness.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "correction_test_scenes.hpp"

namespace tofnav {
namespace {

using testing::TrueModel;

const Eigen::Vector3d kSemiAxesMm(80.0, 95.0, 110.0);

Eigen::Vector3d EllipsoidPoint(double a, double b) {
  return {kSemiAxesMm.x() * std::sin(a) * std::cos(b), kSemiAxesMm.y() * std::sin(a) * std::sin(b),
          kSemiAxesMm.z() * std::cos(a)};
}

Eigen::Vector3d EllipsoidNormal(const Eigen::Vector3d& p) {
  return p.cwiseQuotient(kSemiAxesMm.cwiseProduct(kSemiAxesMm)).normalized();
}

// The skin in `image` (the ellipsoid's own frame), about 2 mm apart.
SurfaceIndex EllipsoidSkin() {
  PointCloud skin;
  for (int i = 0; i < 180; ++i) {
    for (int j = 0; j < 300; ++j) {
      const Eigen::Vector3d p = EllipsoidPoint((i + 0.5) * M_PI / 180, j * 2 * M_PI / 300);
      skin.points.push_back(p);
      skin.normals.push_back(EllipsoidNormal(p));
    }
  }
  return SurfaceIndex(skin);
}

// A frame seeing the head from `ahat_from_image`: the visible samples measured with `model`;
// the tool is the image frame itself (tool_from_ahat = image_from_ahat).
IdentificationFrame View(int index, const Rigid3d& ahat_from_image, const DepthErrorModel& model) {
  IdentificationFrame frame;
  frame.index = index;
  for (int i = 0; i < 60; ++i) {
    for (int j = 0; j < 60; ++j) {
      const Eigen::Vector3d p_image = EllipsoidPoint((i + 0.5) * M_PI / 60, j * 2 * M_PI / 60);
      const Eigen::Vector3d p = ahat_from_image * p_image;
      const Eigen::Vector3d n = ahat_from_image.rotation * EllipsoidNormal(p_image);
      const Eigen::Vector3d ray = p.normalized();
      const double cosine = -ray.dot(n);
      if (cosine < 0.5) continue;  // back faces and grazing views
      const double d = p.norm(), theta = std::acos(cosine);
      frame.head.push_back({ray.cast<float>(), static_cast<float>(d + model.BiasMm(d, theta)),
                            static_cast<float>(theta), 130.0f});
    }
  }
  frame.tool_from_ahat = ahat_from_image.Inverse();
  return frame;
}

// Four views from different sides at 350-650 mm.
std::vector<IdentificationFrame> Views(const DepthErrorModel& model) {
  std::vector<IdentificationFrame> frames;
  for (int k = 0; k < 4; ++k) {
    const Eigen::Quaterniond r(Eigen::AngleAxisd(0.6 * k - 0.9, Eigen::Vector3d::UnitY()) *
                               Eigen::AngleAxisd(0.3 * (k % 2), Eigen::Vector3d::UnitX()));
    frames.push_back(
        View(k, Rigid3d(r, Eigen::Vector3d(10.0 * k, -5.0, 350.0 + 100.0 * k)), model));
  }
  return frames;
}

double MedianAbs(const std::vector<std::vector<double>>& per_frame) {
  std::vector<double> all;
  for (const auto& v : per_frame) {
    for (double d : v) all.push_back(std::abs(d));
  }
  std::nth_element(all.begin(), all.begin() + std::ssize(all) / 2, all.end());
  return all[all.size() / 2];
}

TEST(JointCorrectnessDistances, TheTrueModelPutsEveryViewOnTheSkinAndNoModelCannot) {
  constexpr double kSkinTolMm = 0.05;  // point-to-plane to a 2 mm sampling of a >= 80 mm radius
  const SurfaceIndex skin = EllipsoidSkin();
  const std::vector<IdentificationFrame> frames = Views(TrueModel());
  const std::vector<int> all = {0, 1, 2, 3};
  const Rigid3d guess(Eigen::Quaterniond(Eigen::AngleAxisd(0.01, Eigen::Vector3d::UnitZ())),
                      Eigen::Vector3d(1.0, -1.0, 1.5));
  const JointCorrectness good = JointCorrectnessDistances(frames, all, TrueModel(), skin, guess);
  ASSERT_EQ(good.head_distances.size(), 4u);
  EXPECT_LT(MedianAbs(good.head_distances), kSkinTolMm);
  EXPECT_LT(TranslationDistanceMm(good.image_from_tool, Rigid3d::Identity()), 0.05);
  // Uncorrected, each view lies 6-11 mm too far along its own rays. One rigid placement takes
  // out what the views share (measured: all but about 1 mm); what is left, ten times the skin
  // tolerance, is what makes the offset observable (a per-frame ICP takes out nearly all of it).
  const JointCorrectness bad =
      JointCorrectnessDistances(frames, all, DepthErrorModel{}, skin, guess);
  EXPECT_GT(MedianAbs(bad.head_distances), 10.0 * kSkinTolMm);
}

TEST(JointCorrectnessDistances, ThrowsOnAFrameWithoutAToolPose) {
  std::vector<IdentificationFrame> frames = Views(TrueModel());
  frames[2].tool_from_ahat.reset();
  const std::vector<int> all = {0, 1, 2, 3};
  EXPECT_THROW(JointCorrectnessDistances(frames, all, TrueModel(), EllipsoidSkin(), Rigid3d()),
               std::invalid_argument);
}

TEST(MeanImageFromTool, AveragesConsistentPlacementsAcrossTheQuaternionSign) {
  constexpr double kTol = 1e-9;  // exact arithmetic up to rounding
  const std::vector<IdentificationFrame> frames = Views(TrueModel());
  const Rigid3d image_from_tool(
      Eigen::Quaterniond(Eigen::AngleAxisd(2.0, Eigen::Vector3d(1, 2, 3).normalized())),
      Eigen::Vector3d(5.0, 6.0, 7.0));
  std::vector<Rigid3d> image_from_ahat;
  for (const IdentificationFrame& f : frames) {
    image_from_ahat.push_back(image_from_tool * *f.tool_from_ahat);
  }
  image_from_ahat[1].rotation.coeffs() *= -1.0;  // the same rotation
  const std::vector<int> all = {0, 1, 2, 3};
  const std::optional<Rigid3d> mean = MeanImageFromTool(frames, all, image_from_ahat);
  ASSERT_TRUE(mean.has_value());
  EXPECT_LT(RotationDistanceRad(*mean, image_from_tool), kTol);
  EXPECT_LT(TranslationDistanceMm(*mean, image_from_tool), kTol);
  std::vector<IdentificationFrame> untracked = frames;
  for (IdentificationFrame& f : untracked) f.tool_from_ahat.reset();
  EXPECT_FALSE(MeanImageFromTool(untracked, all, image_from_ahat).has_value());
}

}  // namespace
}  // namespace tofnav
