// SPDX-License-Identifier: BSD-3-Clause
// DefineTool from noisy, flickering, shuffled, cluttered frames of a static or moving tool.
#include "tofnav/tracking/tool_definition.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "tracking_test_tools.hpp"

namespace tofnav {
namespace {

using testing::ReferenceTool;

constexpr double kNoiseMm = 0.2;
constexpr double kDistanceTolMm = 0.1;  // ~ noise * sqrt(2 / frames observed) * 4

std::vector<std::vector<DetectedMarker>> Recording(bool moving, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::bernoulli_distribution flicker(0.1), spurious(0.3);
  const Rigid3d still = testing::FacingToolPose({10.0, -5.0, 420.0}, 0.2, 0.5);
  std::vector<std::vector<DetectedMarker>> frames;
  for (int f = 0; f < 80; ++f) {
    const Rigid3d pose = moving ? testing::RandomFacingPose(rng, 380.0 + f) : still;
    std::vector<DetectedMarker> all = testing::ToolDetections(ReferenceTool(), pose, kNoiseMm, rng);
    std::vector<DetectedMarker> frame;
    for (const DetectedMarker& m : all) {
      if (!flicker(rng)) frame.push_back(m);
    }
    if (spurious(rng)) testing::AddSpurious(frame, 1, rng, pose.translation, 200.0);
    std::shuffle(frame.begin(), frame.end(), rng);
    frames.push_back(frame);
  }
  return frames;
}

void ExpectSameDistances(const ToolGeometry& defined, const ToolGeometry& truth) {
  ASSERT_EQ(defined.markers_in_tool.size(), truth.markers_in_tool.size());
  std::vector<double> a, b;
  for (std::size_t i = 0; i < 4; ++i) {
    for (std::size_t j = i + 1; j < 4; ++j) {
      a.push_back((defined.markers_in_tool[i] - defined.markers_in_tool[j]).norm());
      b.push_back((truth.markers_in_tool[i] - truth.markers_in_tool[j]).norm());
    }
  }
  std::sort(a.begin(), a.end());
  std::sort(b.begin(), b.end());
  for (std::size_t k = 0; k < a.size(); ++k) EXPECT_NEAR(a[k], b[k], kDistanceTolMm) << k;
}

TEST(DefineTool, RecoversAStaticToolDespiteFlickerAndClutter) {
  const auto frames = Recording(false, 1);
  const ToolDefinitionResult r = DefineTool(frames);
  ExpectSameDistances(r.tool, ReferenceTool());
  EXPECT_GE(r.frames_used, 70);
  // Kabsch absorbs 6 of the 12 coordinates per frame: rms^2 = 3 sigma^2 (12 - 6) / 12.
  EXPECT_NEAR(r.definition_rms_mm, kNoiseMm * std::sqrt(1.5), 0.03);
  ASSERT_EQ(r.marker_rms_mm.size(), 4u);
  // The tool frame: centroid at the origin.
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : r.tool.markers_in_tool) centroid += p;
  EXPECT_LT(centroid.norm(), 1e-9);
  EXPECT_EQ(r.ahat_from_tool.size(), frames.size());
}

TEST(DefineTool, RecoversAMovingTool) {
  const ToolDefinitionResult r = DefineTool(Recording(true, 2));
  ExpectSameDistances(r.tool, ReferenceTool());
  EXPECT_GE(r.frames_used, 70);
}

TEST(DefineTool, RefusesRecordingsWithoutEnoughConsistentFrames) {
  std::vector<std::vector<DetectedMarker>> frames(30);  // empty frames
  EXPECT_THROW(DefineTool(frames), std::invalid_argument);
  auto few = Recording(false, 3);
  few.resize(10);
  EXPECT_THROW(DefineTool(few), std::invalid_argument);  // fewer than min_frames
  ToolDefinitionOptions bad;
  bad.marker_count = 2;
  EXPECT_THROW(DefineTool(few, bad), std::invalid_argument);
}

}  // namespace
}  // namespace tofnav
