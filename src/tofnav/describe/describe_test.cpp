// SPDX-License-Identifier: BSD-3-Clause
#include "tofnav/describe/describe.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "tofnav/io/io_error.hpp"
#include "tofnav/mesh/mesh_io.hpp"
#include "tofnav/recording/hl2ss_calibration.hpp"
#include "tofnav/recording/hl2ss_recording.hpp"
#include "tofnav/recording/hl2ss_test_files.hpp"

namespace tofnav {
namespace {

using hl2ss_test::TempPath;

TEST(Describe, RecordingStatisticsMatchTheWrittenFrames) {
  const auto path = TempPath("rec.bin");
  Hl2ssRecordingWriter writer(path);
  for (int k = 0; k < 4; ++k) {
    AhatFrame frame;
    frame.host_ticks = 5'000'000 + static_cast<std::uint64_t>(k) * 222'222;  // 45 Hz
    frame.range_mm = Image<std::uint16_t>(kAhatWidth, kAhatHeight, 0);
    frame.ab = Image<std::uint16_t>(kAhatWidth, kAhatHeight, 100);
    for (int u = 0; u < kAhatWidth; ++u) frame.range_mm(u, 10) = 400;  // one valid row
    frame.range_mm(0, 11) = 401;
    frame.ab(3, 3) = 60000;
    if (k < 3) frame.world_from_rig = Rigid3d::Identity();
    writer.Append(frame);
  }
  writer.Close();

  const auto json = nlohmann::json::parse(DescribeAsJson(path, {.sample_frames = 0}));
  EXPECT_EQ(json["kind"], "recording");
  EXPECT_EQ(json["format"], "hl2ss SAME+RAW");
  EXPECT_EQ(json["timing"]["frames"], 4);
  EXPECT_NEAR(json["timing"]["median_rate_hz"].get<double>(), 45.0, 0.01);
  EXPECT_NEAR(json["timing"]["duration_s"].get<double>(), 3 * 0.0222222, 1e-6);
  EXPECT_EQ(json["frames"]["frames_with_pose"], 3);
  EXPECT_NEAR(json["frames"]["valid_depth_fraction"].get<double>(), 513.0 / kAhatPixels, 1e-12);
  EXPECT_EQ(json["frames"]["range_mm"]["min"], 400);
  EXPECT_EQ(json["frames"]["range_mm"]["max"], 401);
  EXPECT_EQ(json["frames"]["ab"]["median"], 100);
  EXPECT_EQ(json["frames"]["ab"]["max"], 60000);
  EXPECT_EQ(json["hl2ss"]["mode"], 1);
  EXPECT_THAT(DescribeAsText(path), ::testing::HasSubstr("median_rate_hz: 45"));
}

TEST(Describe, CalibrationFolderReportsTheCameraModel) {
  const auto folder = TempPath("calibration");
  SyntheticAhatOptions options;
  options.sample_offset_px = 0.0;
  WriteHl2ssCalibration(folder, MakeSyntheticAhatCalibration(options));
  const auto json = nlohmann::json::parse(DescribeAsJson(folder));
  EXPECT_EQ(json["kind"], "calibration");
  EXPECT_EQ(json["sample_offset_px"], 0.0);  // square K: the hl2ss >= v1.0.37 rule
  // Equidistant f = 254 px over the valid centre row: about 115 degrees (docs/ahat.md section 10).
  EXPECT_NEAR(json["centre_row_fov_deg"].get<double>(), 115.3, 1.0);
  EXPECT_GT(json["valid_pixels"].get<int>(), 190000);
}

TEST(Describe, MeshAndUnknownInput) {
  TriangleMesh mesh;
  mesh.vertices = {{0, 0, 0}, {10, 0, 0}, {0, 20, 0}};
  mesh.triangles = {{0, 1, 2}};
  const auto path = TempPath("tri.ply");
  WriteMesh(path, mesh);
  const auto json = nlohmann::json::parse(DescribeAsJson(path));
  EXPECT_EQ(json["kind"], "mesh");
  EXPECT_EQ(json["triangles"], 1);
  EXPECT_DOUBLE_EQ(json["surface_area_mm2"].get<double>(), 100.0);
  EXPECT_THROW(DescribeAsJson(TempPath("nothing.bin")), IoError);
}

}  // namespace
}  // namespace tofnav
