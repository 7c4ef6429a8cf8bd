// SPDX-License-Identifier: BSD-3-Clause
// StreamRecorder capture folders: a hand-made golden capture, writer round trips, damaged files.
#include "tofnav/recording/stream_recorder.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <numbers>
#include <tuple>

#include "matchers.hpp"
#include "tofnav/core/require.hpp"
#include "tofnav/io/io_error.hpp"
#include "tofnav/io/io_test_helpers.hpp"
#include "tofnav/recording/stream_recorder_files.hpp"

namespace tofnav {
namespace {

using testing::AppendEndBlocks;
using testing::AppendEntry;
using testing::Bytes;
using testing::HandHeader;
using testing::TempDir;
using testing::ToBytes;
using testing::WriteBytes;

constexpr double kRotTolRad = 1e-7;   // 9-digit text matrices (see StreamRecorderWriter)
constexpr double kTransTolMm = 1e-5;  // 9 digits of metres for translations below 10 m
constexpr double kLutRelTol = 1e-6;   // f32 unit rays and back: a few float ulps, relative
constexpr std::uint64_t kFiletime = 132900000000000000ULL;  // 2022-02-24, 100 ns since 1601
constexpr const char* kRecorderMode = "0100777";            // what Tar.cpp writes

using Pixel = std::tuple<int, int, std::uint16_t>;

// 512 x 512 P5 bytes written by hand: header, then samples MSB first.
Bytes HandPgm(std::initializer_list<Pixel> pixels, std::uint16_t fill = 0,
              std::string_view header = "P5\n512 512\n65535\n") {
  Bytes pgm = ToBytes(header);
  pgm.resize(header.size() + 2 * 512 * 512, 0);
  for (std::size_t i = header.size(); i < pgm.size(); i += 2) {
    pgm[i] = static_cast<std::uint8_t>(fill >> 8);
    pgm[i + 1] = static_cast<std::uint8_t>(fill & 0xFF);
  }
  for (const auto& [u, v, value] : pixels) {
    const std::size_t at = header.size() + 2 * static_cast<std::size_t>(v * 512 + u);
    pgm[at] = static_cast<std::uint8_t>(value >> 8);
    pgm[at + 1] = static_cast<std::uint8_t>(value & 0xFF);
  }
  return pgm;
}

void AddHand(Bytes& tar, const std::string& name, const Bytes& data) {
  AppendEntry(tar, HandHeader(name, data.size(), '0', kRecorderMode, 1645700000), data);
}

// LUT with every entry z = 0 (invalid) except the listed unit rays.
void WriteHandLut(const std::filesystem::path& folder,
                  std::initializer_list<std::tuple<int, int, Eigen::Vector3f>> rays = {}) {
  Bytes lut(kStreamRecorderLutBytes, 0);
  for (const auto& [u, v, ray] : rays) {
    std::memcpy(lut.data() + 12 * static_cast<std::size_t>(v * 512 + u), ray.data(), 12);
  }
  WriteBytes(folder / kStreamRecorderLut, lut);
}

// ahat_from_rig: 90 degrees about z, (0.01, -0.02, 0.03) m; so rig_from_ahat is -90 degrees
// about z with translation (20, 10, -30) mm.
constexpr const char* kHandExtrinsics = "0,-1,0,0.01,1,0,0,-0.02,0,0,1,0.03,0,0,0,1\n";
const Rigid3d kHandRigFromAhat{
    Eigen::Quaterniond(Eigen::AngleAxisd(-std::numbers::pi / 2, Eigen::Vector3d::UnitZ())),
    {20.0, 10.0, -30.0}};

void WriteGoldenCapture(const std::filesystem::path& folder) {
  Bytes tar;
  const std::string ts = std::to_string(kFiletime);
  AddHand(tar, ts + "_ab.pgm", HandPgm({{0, 0, 4095}, {3, 4, 0x1234}, {511, 511, 65535}}));
  AddHand(tar, "readme.txt", ToBytes("not a frame"));
  AddHand(tar, ts + ".pgm", HandPgm({{0, 0, 4095}, {1, 0, 4090}, {2, 0, 4089}, {100, 200, 523}}));
  AppendEndBlocks(tar);
  WriteBytes(folder / kStreamRecorderTar, tar);
  WriteHandLut(folder, {{10, 20, {0.6F, 0.0F, 0.8F}}, {256, 256, {0.0F, 0.0F, 1.0F}}});
  WriteBytes(folder / kStreamRecorderExtrinsics, ToBytes(kHandExtrinsics));
  WriteBytes(folder / kStreamRecorderRig2World,
             ToBytes(ts + ",1,0,0,0.5,0,1,0,-0.25,0,0,1,2,0,0,0,1\n" +
                     "132900000000500000,1,0,0,0,0,1,0,0,0,0,1,0,0,0,0,1\n"));
}

TEST(StreamRecorderCapture, ReadsTheHandMadeGoldenCapture) {
  const TempDir dir("sr_golden");
  WriteGoldenCapture(dir.path());
  const auto capture = StreamRecorderCapture::Open(dir.path());
  EXPECT_EQ(capture->format(), "StreamRecorder");
  ASSERT_EQ(capture->frame_count(), 1U);
  EXPECT_EQ(capture->host_ticks(0), kFiletime);
  EXPECT_EQ(capture->report().other_entries, 1U);
  EXPECT_EQ(capture->unpaired_frames(), 0U);
  EXPECT_EQ(capture->report().unposed_frames, 0U);

  const AhatFrame frame = capture->ReadFrame(0);
  EXPECT_EQ(frame.host_ticks, kFiletime);
  EXPECT_EQ(frame.range_mm(0, 0), 0);  // 4095 and 4090 are invalid codes
  EXPECT_EQ(frame.range_mm(1, 0), 0);
  EXPECT_EQ(frame.range_mm(2, 0), 4089);
  EXPECT_EQ(frame.range_mm(100, 200), 523);
  EXPECT_EQ(frame.range_mm(101, 200), 0);
  EXPECT_EQ(frame.ab(0, 0), 4095);  // AB is raw
  EXPECT_EQ(frame.ab(3, 4), 0x1234);
  EXPECT_EQ(frame.ab(511, 511), 65535);
  ASSERT_TRUE(frame.world_from_rig.has_value());
  EXPECT_THAT(*frame.world_from_rig,
              RigidNear(Rigid3d(Eigen::Quaterniond::Identity(), {500.0, -250.0, 2000.0}),
                        kRotTolRad, kTransTolMm));

  const std::optional<AhatCalibration> calibration = capture->calibration();
  ASSERT_TRUE(calibration.has_value());
  EXPECT_EQ(calibration->sample_offset_px, 0.5);
  EXPECT_NEAR(calibration->uv2xy(10, 20).x(), 0.75, kLutRelTol);
  EXPECT_NEAR(calibration->uv2xy(10, 20).y(), 0.0, kLutRelTol);
  EXPECT_EQ(calibration->uv2xy(256, 256), Eigen::Vector2f::Zero());
  EXPECT_TRUE(std::isnan(calibration->uv2xy(0, 0).x()));
  EXPECT_THAT(calibration->rig_from_ahat, RigidNear(kHandRigFromAhat, kRotTolRad, kTransTolMm));
}

TEST(StreamRecorderCapture, PairsByTimestampSortsAndCountsUnpaired) {
  const TempDir dir("sr_pairs");
  Bytes tar;
  for (const char* name : {"3000_ab.pgm", "3000.pgm", "2000.pgm", "1000.pgm", "1000_ab.pgm",
                           "4000_ab.pgm", "12.PGM", "x1000.pgm", "_ab.pgm"}) {
    const std::string text = name;
    const auto ts = static_cast<std::uint16_t>(std::atoi(name) / 1000);  // 0 for the others
    AddHand(tar, text,
            HandPgm({}, static_cast<std::uint16_t>(
                            ts + (text.find("_ab") != std::string::npos ? 100 : 0))));
  }
  WriteBytes(dir.path() / kStreamRecorderTar, tar);  // and no end blocks
  WriteHandLut(dir.path());
  WriteBytes(dir.path() / kStreamRecorderExtrinsics, ToBytes(kHandExtrinsics));
  const auto capture = StreamRecorderCapture::Open(dir.path());
  ASSERT_EQ(capture->frame_count(), 2U);
  EXPECT_EQ(capture->host_ticks(0), 1000U);
  EXPECT_EQ(capture->host_ticks(1), 3000U);
  EXPECT_EQ(capture->unpaired_frames(), 2U);  // 2000 (range only), 4000 (AB only)
  EXPECT_EQ(capture->report().other_entries, 3U);
  EXPECT_EQ(capture->report().unposed_frames, 2U);  // no rig2world file at all
  EXPECT_EQ(capture->tar_index().end, TarEnd::kEndOfFile);
  const AhatFrame frame = capture->ReadFrame(1);
  EXPECT_EQ(frame.range_mm(7, 7), 3);
  EXPECT_EQ(frame.ab(7, 7), 103);
  EXPECT_FALSE(frame.world_from_rig.has_value());
  EXPECT_EQ(capture->NearestFrame(2500), 1U);
}

AhatCalibration HandCalibration() {
  AhatCalibration calibration;
  calibration.uv2xy = Image<Eigen::Vector2f>(512, 512, Eigen::Vector2f::Zero());
  for (int v = 0; v < 512; ++v) {
    for (int u = 0; u < 512; ++u) {
      const double du_px = u - 252.4;
      const double dv_px = v - 252.8;
      const bool inside = du_px * du_px + dv_px * dv_px <= 300.0 * 300.0;
      calibration.uv2xy(u, v) = inside ? Eigen::Vector2f(static_cast<float>(du_px / 254.0),
                                                         static_cast<float>(dv_px / 254.0))
                                       : Eigen::Vector2f::Constant(std::nanf(""));
    }
  }
  calibration.rig_from_ahat =
      Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized())),
              {21.2, -59.2, 11.8});
  return calibration;
}

// Frames with pixel-varying content (a multiplicative hash, cheap even unoptimised).
std::vector<AhatFrame> PatternFrames(int count) {
  std::vector<AhatFrame> frames(static_cast<std::size_t>(count));
  for (int k = 0; k < count; ++k) {
    AhatFrame& frame = frames[static_cast<std::size_t>(k)];
    frame.host_ticks = kFiletime + static_cast<std::uint64_t>(k) * 222222;  // 22.2 ms apart
    frame.range_mm = Image<std::uint16_t>(512, 512);
    frame.ab = Image<std::uint16_t>(512, 512);
    std::uint32_t hash = 7U + static_cast<std::uint32_t>(k);
    for (std::size_t i = 0; i < frame.range_mm.size(); ++i) {
      hash = hash * 1664525U + 1013904223U;
      frame.range_mm.pixels()[i] = static_cast<std::uint16_t>((hash >> 8) % 4090U);  // valid
      frame.ab.pixels()[i] = static_cast<std::uint16_t>(hash >> 16);
    }
    if (k != 1) {  // frame 1 was not located
      frame.world_from_rig = Rigid3d(
          Eigen::Quaterniond(Eigen::AngleAxisd(0.5 + k, Eigen::Vector3d(k, 1, -2).normalized())),
          {1234.5 - 300.0 * k, -87.6, 1520.3 + k});
    }
  }
  return frames;
}

void WriteCapture(const std::filesystem::path& folder, const std::vector<AhatFrame>& frames) {
  StreamRecorderWriter writer(folder, HandCalibration());
  for (const AhatFrame& frame : frames) writer.Append(frame);
  writer.Close();
}

TEST(StreamRecorderWriter, RoundTripsFramesPosesAndCalibration) {
  const TempDir dir("sr_round_trip");
  const std::vector<AhatFrame> frames = PatternFrames(3);
  WriteCapture(dir.path(), frames);
  const auto capture = StreamRecorderCapture::Open(dir.path());
  ASSERT_EQ(capture->frame_count(), 3U);
  EXPECT_EQ(capture->tar_index().end, TarEnd::kEndBlocks);
  EXPECT_EQ(capture->report().unposed_frames, 1U);
  for (std::size_t k = 0; k < 3; ++k) {
    const AhatFrame frame = capture->ReadFrame(k);
    EXPECT_EQ(frame.host_ticks, frames[k].host_ticks);
    EXPECT_EQ(frame.range_mm, frames[k].range_mm);
    EXPECT_EQ(frame.ab, frames[k].ab);
    ASSERT_EQ(frame.world_from_rig.has_value(), frames[k].world_from_rig.has_value());
    if (frame.world_from_rig) {
      EXPECT_THAT(*frame.world_from_rig,
                  RigidNear(*frames[k].world_from_rig, kRotTolRad, kTransTolMm));
    }
  }
  const AhatCalibration truth = HandCalibration();
  const AhatCalibration read = *capture->calibration();
  EXPECT_THAT(read.rig_from_ahat, RigidNear(truth.rig_from_ahat, kRotTolRad, kTransTolMm));
  for (int v = 0; v < 512; v += 7) {
    for (int u = 0; u < 512; u += 5) {
      const Eigen::Vector2f& expected = truth.uv2xy(u, v);
      ASSERT_EQ(std::isnan(read.uv2xy(u, v).x()), std::isnan(expected.x())) << u << "," << v;
      if (!std::isnan(expected.x())) {
        EXPECT_LT((read.uv2xy(u, v) - expected).norm(), kLutRelTol * (1.0 + expected.norm()));
      }
    }
  }
}

TEST(StreamRecorderCapture, TruncatedTarsKeepTheCompleteFrames) {
  const TempDir dir("sr_truncated");
  WriteCapture(dir.path(), PatternFrames(2));
  const std::filesystem::path tar = dir.path() / kStreamRecorderTar;
  const std::uintmax_t size = std::filesystem::file_size(tar);
  std::filesystem::resize_file(tar, size - 1024);  // killed before the end blocks
  EXPECT_EQ(StreamRecorderCapture::Open(dir.path())->frame_count(), 2U);
  std::filesystem::resize_file(tar, size - 1024 - 1000);  // killed inside the last range PGM
  const auto capture = StreamRecorderCapture::Open(dir.path());
  EXPECT_EQ(capture->frame_count(), 1U);
  EXPECT_EQ(capture->unpaired_frames(), 1U);  // its AB entry survived
  EXPECT_EQ(capture->tar_index().end, TarEnd::kTruncatedEntry);
  EXPECT_EQ(capture->tar_index().dropped_name, std::to_string(kFiletime + 222222) + ".pgm");
}

// The IoError that Open or ReadFrame(0) throws.
IoError CaptureError(const std::filesystem::path& folder) {
  try {
    StreamRecorderCapture::Open(folder)->ReadFrame(0);
  } catch (const IoError& error) {
    return error;
  }
  ADD_FAILURE() << "no IoError";
  return IoError("", std::nullopt, "");
}

TEST(StreamRecorderCapture, MissingAndMalformedFilesAreNamed) {
  const TempDir dir("sr_missing");
  WriteGoldenCapture(dir.path());
  std::filesystem::remove(dir.path() / kStreamRecorderRig2World);  // optional
  EXPECT_FALSE(StreamRecorderCapture::Open(dir.path())->ReadFrame(0).world_from_rig.has_value());

  const std::string ts = std::to_string(kFiletime);
  WriteBytes(dir.path() / kStreamRecorderRig2World,
             ToBytes(ts + ",1,0,0,0,0,1,0,0,0,0,1,0,0,0,0,1\n" + ts + "1,bad\n"));
  IoError error = CaptureError(dir.path());
  EXPECT_EQ(error.path().filename().string(), kStreamRecorderRig2World);
  EXPECT_EQ(error.offset(), ts.size() + 33);  // the second line
  std::filesystem::remove(dir.path() / kStreamRecorderRig2World);

  std::filesystem::rename(dir.path() / kStreamRecorderExtrinsics, dir.path() / "e");
  EXPECT_EQ(CaptureError(dir.path()).path().filename().string(), kStreamRecorderExtrinsics);
  std::filesystem::rename(dir.path() / "e", dir.path() / kStreamRecorderExtrinsics);

  std::filesystem::remove(dir.path() / kStreamRecorderLut);
  error = CaptureError(dir.path());
  EXPECT_EQ(error.path().filename().string(), kStreamRecorderLut);
  EXPECT_NE(std::string(error.what()).find(kStreamRecorderLut), std::string::npos);
  WriteBytes(dir.path() / kStreamRecorderLut, Bytes(100, 0));
  EXPECT_EQ(CaptureError(dir.path()).offset(), 100U);
}

TEST(StreamRecorderCapture, BadPgmEntriesFailAtTheirOffsetInTheTar) {
  const TempDir dir("sr_bad_pgm");
  WriteGoldenCapture(dir.path());
  Bytes tar;
  AddHand(tar, "5_ab.pgm", HandPgm({}, 0, "P5\n512 512\n255\n"));
  AddHand(tar, "5.pgm", HandPgm({}));
  AddHand(tar, "6_ab.pgm", ToBytes(std::string_view("P5\n2 1\n65535\n\0\0\0\0", 17)));
  AddHand(tar, "6.pgm", HandPgm({}));
  WriteBytes(dir.path() / kStreamRecorderTar, tar);
  const auto capture = StreamRecorderCapture::Open(dir.path());
  ASSERT_EQ(capture->frame_count(), 2U);
  try {
    capture->ReadFrame(0);
    ADD_FAILURE() << "no IoError";
  } catch (const IoError& error) {
    EXPECT_EQ(error.path().filename().string(), kStreamRecorderTar);
    EXPECT_EQ(error.offset(), 512U + 11U);  // data of the first entry + the maxval position
  }
  EXPECT_THROW(capture->ReadFrame(1), IoError);  // 2 x 1 is not an AHAT frame
  EXPECT_THROW(capture->ReadFrame(2), PreconditionError);
}

TEST(StreamRecorderWriter, PreconditionsAndNothingWithoutClose) {
  const TempDir dir("sr_writer");
  AhatCalibration wrong_offset = HandCalibration();
  wrong_offset.sample_offset_px = 0.0;
  EXPECT_THROW(StreamRecorderWriter(dir.path() / "a", wrong_offset), PreconditionError);
  {
    StreamRecorderWriter writer(dir.path() / "b", HandCalibration());
    std::vector<AhatFrame> frames = PatternFrames(2);
    writer.Append(frames[0]);
    EXPECT_THROW(writer.Append(frames[0]), PreconditionError);  // same timestamp
    frames[1].ab = Image<std::uint16_t>(4, 4);
    EXPECT_THROW(writer.Append(frames[1]), PreconditionError);
  }
  EXPECT_TRUE(std::filesystem::is_empty(dir.path() / "b"));
}

}  // namespace
}  // namespace tofnav
