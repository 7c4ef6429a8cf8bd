// SPDX-License-Identifier: BSD-3-Clause
#include "tofnav/recording/convert.hpp"

#include <gtest/gtest.h>

#include "hl2ss_test_files.hpp"
#include "matchers.hpp"
#include "tofnav/io/file.hpp"
#include "tofnav/io/io_error.hpp"
#include "tofnav/recording/hl2ss_calibration.hpp"
#include "tofnav/recording/hl2ss_recording.hpp"
#include "tofnav/recording/open_recording.hpp"
#include "tofnav/recording/zdepth.hpp"
#include "tofnav/sensor/ahat_camera.hpp"

namespace tofnav {
namespace {

using hl2ss_test::TempPath;

constexpr double kPoseRotTolRad = 1e-6;  // poses pass through f32 (hl2ss) or 9 digits (text)
constexpr double kPoseTransTolMm = 1e-3;
constexpr float kRayTol = 1e-6F;  // f32 unit rays

std::vector<AhatFrame> TestFrames() {
  std::vector<AhatFrame> frames;
  for (int k = 0; k < 3; ++k) {
    AhatFrame frame;
    frame.host_ticks = 1'000'000 + static_cast<std::uint64_t>(k) * 222'222;
    frame.range_mm = Image<std::uint16_t>(kAhatWidth, kAhatHeight);
    frame.ab = Image<std::uint16_t>(kAhatWidth, kAhatHeight);
    for (int v = 0; v < kAhatHeight; ++v) {
      for (int u = 0; u < kAhatWidth; ++u) {
        frame.range_mm(u, v) = static_cast<std::uint16_t>((u * 7 + v * 3 + k * 11) % 1100);
        frame.ab(u, v) = static_cast<std::uint16_t>((u * v + k) % 65536);
      }
    }
    if (k != 1) {  // the middle frame was not located
      frame.world_from_rig =
          Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(0.3 * k, Eigen::Vector3d::UnitY())),
                  Eigen::Vector3d(10.0 * k, -250.0, 1125.5));
    }
    frames.push_back(std::move(frame));
  }
  return frames;
}

std::filesystem::path WriteRaw(const std::vector<AhatFrame>& frames) {
  const auto path = TempPath("raw.bin");
  Hl2ssRecordingWriter writer(path);
  for (const AhatFrame& f : frames) writer.Append(f);
  writer.Close();
  return path;
}

void ExpectSamePoses(const AhatRecording& out, const std::vector<AhatFrame>& frames) {
  ASSERT_EQ(out.frame_count(), frames.size());
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const AhatFrame read = out.ReadFrame(i);
    EXPECT_EQ(read.host_ticks, frames[i].host_ticks);
    ASSERT_EQ(read.world_from_rig.has_value(), frames[i].world_from_rig.has_value());
    if (read.world_from_rig) {
      EXPECT_THAT(*read.world_from_rig,
                  RigidNear(*frames[i].world_from_rig, kPoseRotTolRad, kPoseTransTolMm));
    }
  }
}

TEST(ConvertRecording, RawToZdepthQuantisesAsTheFormatDoes) {
  const std::vector<AhatFrame> frames = TestFrames();
  const auto input = OpenAhatRecording(WriteRaw(frames));
  const auto output = TempPath("zdepth.bin");
  const ConvertResult result =
      ConvertRecording(*input, output, {.format = RecordingFormat::kHl2ssZdepth});
  EXPECT_EQ(result.frames_written, 3u);
  EXPECT_EQ(result.frames_with_pose, 2u);
  const auto converted = OpenAhatRecording(output);
  EXPECT_EQ(converted->format(), "hl2ss ZDEPTH+RAW");
  ExpectSamePoses(*converted, frames);
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const AhatFrame read = converted->ReadFrame(i);
    for (std::size_t p = 0; p < read.range_mm.size(); ++p) {
      ASSERT_EQ(read.range_mm.pixels()[p], ZdepthRoundTripMm(frames[i].range_mm.pixels()[p]));
      ASSERT_EQ(read.ab.pixels()[p], frames[i].ab.pixels()[p]);
    }
  }
}

TEST(ConvertRecording, RawToStreamRecorderIsExactAndResamplesTheTable) {
  const std::vector<AhatFrame> frames = TestFrames();
  SyntheticAhatOptions synthetic;
  synthetic.sample_offset_px = 0.0;  // hl2ss >= v1.0.36 table: needs re-sampling for the LUT
  const AhatCalibration calibration = MakeSyntheticAhatCalibration(synthetic);
  const auto input = OpenAhatRecording(WriteRaw(frames));
  const auto folder = TempPath("capture");
  ConvertOptions options{.format = RecordingFormat::kStreamRecorder, .calibration = calibration};
  std::size_t last_progress = 0;
  options.progress = [&](std::size_t done, std::size_t total) {
    EXPECT_EQ(total, 3u);
    last_progress = done;
  };
  ConvertRecording(*input, folder, options);
  EXPECT_EQ(last_progress, 3u);

  const auto converted = OpenAhatRecording(folder);
  EXPECT_EQ(converted->format(), "StreamRecorder");
  ExpectSamePoses(*converted, frames);
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const AhatFrame read = converted->ReadFrame(i);
    EXPECT_EQ(read.range_mm, frames[i].range_mm);
    EXPECT_EQ(read.ab, frames[i].ab);
  }
  // The LUT gives the same pixel rays as the original s = 0 table.
  const AhatCamera original(calibration);
  const AhatCamera from_lut(*converted->calibration());
  for (int v = 0; v < kAhatHeight; v += 7) {
    for (int u = 0; u < kAhatWidth; u += 7) {
      if (!original.IsValid(u, v)) continue;
      ASSERT_TRUE(from_lut.IsValid(u, v)) << u << "," << v;
      ASSERT_LT((original.PixelRay(u, v) - from_lut.PixelRay(u, v)).norm(), kRayTol);
    }
  }
}

TEST(ConvertRecording, StreamRecorderOutputNeedsACalibration) {
  const auto input = OpenAhatRecording(WriteRaw(TestFrames()));
  EXPECT_THROW(
      ConvertRecording(*input, TempPath("capture"), {.format = RecordingFormat::kStreamRecorder}),
      PreconditionError);
  EXPECT_FALSE(std::filesystem::exists(TempPath("capture") / "Depth AHaT.tar"));
}

TEST(OpenAhatRecording, RejectsOtherFilesWithTheirName) {
  const auto path = TempPath("not_a_recording.bin");
  WriteFileAtomically(path, std::string(100, '7'));
  try {
    OpenAhatRecording(path);
    FAIL();
  } catch (const IoError& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("not_a_recording.bin"));
    EXPECT_THAT(e.what(), ::testing::HasSubstr("HL2SSV23"));
  }
  EXPECT_THROW(OpenAhatRecording(TempPath("missing.bin")), IoError);
  std::filesystem::create_directories(TempPath("empty_folder"));
  EXPECT_THROW(OpenAhatRecording(TempPath("empty_folder")), IoError);
}

}  // namespace
}  // namespace tofnav
