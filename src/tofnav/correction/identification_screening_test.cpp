// SPDX-License-Identifier: BSD-3-Clause
// Foreground screening and marker grouping on a sphere "head" seen from a moving headset, with a
// "hand" plate passing between the camera and the head in some frames.
#include "tofnav/correction/identification_screening.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "tofnav/sim/motion.hpp"

namespace tofnav {
namespace {

constexpr double kHeadRadiusMm = 90.0;
constexpr int kFrames = 40;
constexpr int kSamplesPerFrame = 500;

// World camera poses on an arc 450 mm from the head centre (the origin), +-25 deg.
Rigid3d CameraPose(int frame) {
  const double a = (static_cast<double>(frame) / (kFrames - 1) - 0.5) * 50.0 * M_PI / 180.0;
  const Eigen::Vector3d eye(450.0 * std::sin(a), -60.0, 450.0 * std::cos(a));
  return sim::LookAt(eye, Eigen::Vector3d::Zero());
}

SurfaceSample Sample(const Rigid3d& world_from_ahat, const Eigen::Vector3d& p_world) {
  const Eigen::Vector3d p = world_from_ahat.Inverse() * p_world;
  SurfaceSample s;
  s.range_mm = static_cast<float>(p.norm());
  s.ray = (p / p.norm()).cast<float>();
  return s;
}

// Head samples: random points of the sphere cap that faces the camera; with a hand, the points
// of a 70 x 90 mm plate 45 mm above the skin replace the head points it hides.
IdentificationFrame Frame(int index, bool hand, std::mt19937& rng) {
  IdentificationFrame frame;
  frame.index = index;
  const Rigid3d world_from_ahat = CameraPose(index);
  frame.world_from_ahat = world_from_ahat;
  const Eigen::Vector3d eye = world_from_ahat.translation;
  const Eigen::Vector3d hand_centre = (kHeadRadiusMm + 45.0) * eye.normalized();
  const Eigen::Vector3d hand_normal = eye.normalized();
  const Eigen::Vector3d hand_u = hand_normal.cross(Eigen::Vector3d::UnitY()).normalized();
  const Eigen::Vector3d hand_v = hand_normal.cross(hand_u);
  std::normal_distribution<double> gauss;
  std::uniform_real_distribution<double> unit(-0.5, 0.5);
  while (static_cast<int>(frame.head.size()) < kSamplesPerFrame) {
    const Eigen::Vector3d n = Eigen::Vector3d(gauss(rng), gauss(rng), gauss(rng)).normalized();
    const Eigen::Vector3d p = kHeadRadiusMm * n;
    if (n.dot((eye - p).normalized()) < 0.3) continue;  // not facing the camera
    Eigen::Vector3d seen = p;
    if (hand) {
      const Eigen::Vector3d ray = (p - eye).normalized();
      const double t = (hand_centre - eye).dot(hand_normal) / ray.dot(hand_normal);
      const Eigen::Vector3d hit = eye + t * ray - hand_centre;
      if (std::abs(hit.dot(hand_u)) < 35.0 && std::abs(hit.dot(hand_v)) < 45.0)
        seen = hit + hand_centre;
    }
    frame.head.push_back(Sample(world_from_ahat, seen));
  }
  // One sticker patch at the top of the head, its neighbours on the skin around it.
  MarkerPatch patch;
  const Eigen::Vector3d sticker = kHeadRadiusMm * Eigen::Vector3d(0.2, -0.3, 1.0).normalized();
  patch.marker_points.push_back(world_from_ahat.Inverse() * sticker);
  for (int i = 0; i < 60; ++i) {
    const Eigen::Vector3d jitter(unit(rng) * 40.0, unit(rng) * 40.0, unit(rng) * 40.0);
    patch.neighbours.push_back(
        Sample(world_from_ahat, kHeadRadiusMm * (sticker + jitter).normalized()));
  }
  frame.markers.push_back(patch);
  frame.marker_points = patch.marker_points;
  return frame;
}

TEST(ScreenForeground, LeavesOutTheHandAndKeepsTheSkin) {
  std::mt19937 rng(7);
  std::vector<IdentificationFrame> frames;
  for (int f = 0; f < kFrames; ++f) frames.push_back(Frame(f, f >= 12 && f < 20, rng));
  ForegroundScreeningReport report;
  const std::vector<IdentificationFrame> out =
      ScreenForeground(frames, DepthErrorModel{}, {}, report);
  ASSERT_EQ(out.size(), frames.size());
  EXPECT_EQ(report.frames_in, kFrames);
  EXPECT_EQ(report.frames_without_world_pose, 0);
  // Every hand frame loses its hand: the whole frame (the plate is ~25 % of the cap) or at least
  // every point more than 20 mm off the skin.
  for (int f = 12; f < 20; ++f) {
    const auto& frame = out[static_cast<std::size_t>(f)];
    for (const SurfaceSample& s : frame.head) {
      const Eigen::Vector3d p = *frame.world_from_ahat * (s.ray.cast<double>() * s.range_mm);
      EXPECT_LT(p.norm() - kHeadRadiusMm, 20.0) << "frame " << f;
    }
  }
  EXPECT_EQ(report.frames_left_out, 8);
  // Clean frames keep their skin: at most 1 % of their points lost (a cap edge seen by few
  // frames in front of a well-seen one is the only way a skin point can be judged foreground).
  int lost = 0;
  for (int f = 0; f < kFrames; ++f) {
    if (f >= 12 && f < 20) continue;
    lost += kSamplesPerFrame - static_cast<int>(out[static_cast<std::size_t>(f)].head.size());
    EXPECT_EQ(out[static_cast<std::size_t>(f)].markers.size(), 1u) << "frame " << f;
  }
  EXPECT_LT(lost, kSamplesPerFrame * (kFrames - 8) / 100);
}

TEST(ScreenForeground, FramesWithoutAWorldPosePassUnchanged) {
  std::mt19937 rng(3);
  std::vector<IdentificationFrame> frames;
  for (int f = 0; f < 10; ++f) {
    frames.push_back(Frame(f, f == 4, rng));
    frames.back().world_from_ahat.reset();
  }
  ForegroundScreeningReport report;
  const auto out = ScreenForeground(frames, DepthErrorModel{}, {}, report);
  EXPECT_EQ(report.frames_without_world_pose, 10);
  EXPECT_EQ(report.frames_left_out, 0);
  EXPECT_EQ(out[4].head.size(), frames[4].head.size());
}

TEST(GroupMarkerObservations, OneStickerSeenFromEveryFrameIsOneMarker) {
  std::mt19937 rng(5);
  std::vector<IdentificationFrame> frames;
  for (int f = 0; f < 12; ++f) frames.push_back(Frame(f, false, rng));
  std::vector<StickerUse> markers;
  const auto ids = GroupMarkerObservations(frames, 10.0, markers);
  ASSERT_EQ(markers.size(), 1u);
  EXPECT_EQ(markers[0].observations, 12);
  const Eigen::Vector3d truth = kHeadRadiusMm * Eigen::Vector3d(0.2, -0.3, 1.0).normalized();
  EXPECT_NEAR(markers[0].centre_mm[2], truth.z(), 1e-6);  // noise-free: exact up to rounding
  for (const auto& v : ids) EXPECT_EQ(v, std::vector<int>{0});
}

}  // namespace
}  // namespace tofnav
