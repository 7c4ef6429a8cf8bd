// SPDX-License-Identifier: BSD-3-Clause
// Identification with the tracked tools given (labelled slow): on a simulated EVD session, no
// marker of the headframe reaches the sticker fit (Eq. 6), and the skin stickers still do.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "navigation_e2e_case.hpp"
#include "tofnav/pipeline/identify.hpp"

namespace tofnav {
namespace {

// The simulator's frames, held in memory as a recording.
class SimulatedRecording : public AhatRecording {
 public:
  explicit SimulatedRecording(std::vector<AhatFrame> frames) : frames_(std::move(frames)) {}
  std::string format() const override { return "simulated (memory)"; }
  std::size_t frame_count() const override { return frames_.size(); }
  std::uint64_t host_ticks(std::size_t index) const override { return frames_[index].host_ticks; }
  AhatFrame ReadFrame(std::size_t index) const override { return frames_[index]; }
  std::optional<AhatCalibration> calibration() const override { return std::nullopt; }

 private:
  std::vector<AhatFrame> frames_;
};

// A marker whose patch entered Eq. (6) is taken for the true marker nearest its mean centre
// (both in `world`, the simulator's scene) when within this distance: stickers lie >= 25 mm
// apart, and the centres the report gives are within ~2 mm of the truth.
constexpr double kSameMarkerMm = 8.0;

struct MarkerTally {
  int headframe = 0;  // report markers on a headframe tool
  int stickers = 0;   // report markers on a skin sticker
};

// Every marker of the scene in `world` (the patient is still: the first frame's truth holds).
struct TrueMarker {
  std::string tool;
  Eigen::Vector3d centre_in_world;
};

MarkerTally Classify(const DepthModelFitReport& report, const std::vector<TrueMarker>& truth,
                     const std::vector<std::string>& headframe) {
  MarkerTally tally;
  for (const StickerUse& use : report.markers) {
    const Eigen::Vector3d centre(use.centre_mm[0], use.centre_mm[1], use.centre_mm[2]);
    double best = kSameMarkerMm;
    const TrueMarker* nearest = nullptr;
    for (const TrueMarker& m : truth) {
      const double d = (m.centre_in_world - centre).norm();
      if (d < best) best = d, nearest = &m;
    }
    if (nearest == nullptr) continue;
    const bool on_headframe =
        std::find(headframe.begin(), headframe.end(), nearest->tool) != headframe.end();
    (on_headframe ? tally.headframe : tally.stickers) += 1;
  }
  return tally;
}

TEST(IdentifyE2e, TrackedToolMarkersNeverReachTheStickerFit) {
  testing::EvdCase c = testing::MakeEvdCase(40, /*instrument=*/true);
  c.scenario.timing.drop_probability = 0.0;
  sim::Simulator simulator(c.scenario);
  std::vector<AhatFrame> frames;
  std::vector<TrueMarker> truth;
  while (!simulator.done()) {
    sim::SimulatedFrame f = simulator.Next();
    if (truth.empty()) {
      const Rigid3d world_from_ahat = f.world_from_rig_true * simulator.camera().rig_from_ahat();
      for (const sim::MarkerTruth& m : f.render.markers) {
        truth.push_back({c.scenario.scene.tools[static_cast<std::size_t>(m.tool)].name,
                         world_from_ahat * m.centre_in_ahat});
      }
    }
    frames.push_back(std::move(f.render.frame));
  }
  const SimulatedRecording recording(std::move(frames));
  const sim::Tool& left = c.scenario.scene.tools[static_cast<std::size_t>(c.reference)];
  const sim::Tool& right = c.scenario.scene.tools[static_cast<std::size_t>(c.instrument)];
  const std::vector<std::string> headframe = {left.name, right.name};

  IdentifyRecordingOptions options;
  options.exclude_tools = {testing::ToolFromSim(left), testing::ToolFromSim(right)};
  const IdentifyRecordingResult with = IdentifyFromRecording(
      recording, simulator.camera(), c.navigation_case.marker_range, nullptr, options);
  std::int64_t blanked = 0;
  for (const auto& [name, count] : with.tool_marker_observations_left_out) blanked += count;
  // Every frame sees the headframe: most of its markers are found and left out.
  EXPECT_GE(with.frames_with_tool_markers, 35);
  EXPECT_GE(blanked, 35 * 3);
  const MarkerTally kept = Classify(with.file.model.report, truth, headframe);
  EXPECT_EQ(kept.headframe, 0);
  EXPECT_GE(kept.stickers, 3);  // the four forehead stickers, one may be out of view
}

}  // namespace
}  // namespace tofnav
