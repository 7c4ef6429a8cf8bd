// SPDX-License-Identifier: BSD-3-Clause
// camera.calibration.folder: a session rendered through a real device's calibration, whose
// calibration folder is written back byte for byte.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "tofnav/io/file.hpp"
#include "tofnav/io/io_error.hpp"
#include "tofnav/io/io_test_helpers.hpp"
#include "tofnav/recording/hl2ss_calibration.hpp"
#include "tofnav/scenario/scenario_json.hpp"
#include "tofnav/scenario/simulate.hpp"
#include "tofnav/sensor/ahat_camera.hpp"
#include "tofnav/sim/scenario_variation.hpp"
#include "tofnav/sim/simulator.hpp"

namespace tofnav {
namespace {

// A board 500 mm in front of a static camera, rendered ideally through `folder`.
std::string BoardScenario(const std::filesystem::path& folder) {
  return R"({"name": "device", "frames": 2,
    "objects": [{"name": "board", "shape": {"kind": "plane", "width_mm": 3000, "height_mm": 3000},
                 "pose": {"translation_mm": [0, 0, 500]}}],
    "camera": {"calibration": {"folder": ")" +
         folder.string() + R"("}},
    "render": {"preset": "ideal"}})";
}

TEST(SimulateDevice, ARealCalibrationFolderRoundTripsByteForByteAndIsRenderedThrough) {
  const testing::TempDir device("sim_device"), out("sim_device_out");
  // Another headset: the synthetic model perturbed within the spread of real devices.
  const SyntheticAhatOptions options = sim::PerturbedDevice(sim::CameraSetup().calibration, 7);
  WriteHl2ssCalibration(device.path(), MakeSyntheticAhatCalibration(options));
  const sim::Scenario s =
      ParseScenarioJson(BoardScenario(device.path()), device.path() / "scenario.json");
  ASSERT_TRUE(s.camera.device != nullptr);

  SimulateOptions run;
  run.frames = 1;
  RunSimulation(s, out.path(), run);
  int files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(device.path() / "rm_depth_ahat")) {
    const std::filesystem::path copy =
        out.path() / "calibration/rm_depth_ahat" / entry.path().filename();
    EXPECT_EQ(ReadFileBytes(copy), ReadFileBytes(entry.path())) << copy;
    ++files;
  }
  EXPECT_EQ(files, 6);  // uv2xy, extrinsics, intrinsics, undistort_map, scale, alias

  // Each pixel's range is the board's distance along the device's ray (float truth: 0.01 mm),
  // and differs from the synthetic model's by millimetres off-axis (so this can fail).
  constexpr double kFloatTolMm = 0.01, kMinModelDifferenceMm = 0.5;
  sim::Simulator simulator(s);
  const sim::SimulatedFrame frame = simulator.Next();
  const AhatCamera real(*s.camera.device), model(MakeSyntheticAhatCalibration());
  const Eigen::Vector2i pixel(430, 256);
  const double truth_mm = frame.render.truth_range_mm(pixel.x(), pixel.y());
  EXPECT_NEAR(truth_mm, 500.0 / real.Ray(pixel.cast<double>())->z(), kFloatTolMm);
  EXPECT_GT(std::abs(truth_mm - 500.0 / model.Ray(pixel.cast<double>())->z()),
            kMinModelDifferenceMm);
}

TEST(SimulateDevice, AFolderWithSyntheticKeysOrMissingFilesIsRefused) {
  const testing::TempDir device("sim_device_bad");
  EXPECT_THROW(ParseScenarioJson(BoardScenario(device.path() / "missing"), "s.json"), IoError);
  WriteHl2ssCalibration(device.path(), MakeSyntheticAhatCalibration());
  const std::string mixed = R"({"camera": {"calibration": {"folder": ")" + device.path().string() +
                            R"(", "focal_px": 250}}})";
  EXPECT_THROW(ParseScenarioJson(mixed, "s.json"), IoError);
}

}  // namespace
}  // namespace tofnav
