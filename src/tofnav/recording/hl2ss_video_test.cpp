// SPDX-License-Identifier: BSD-3-Clause
// hl2ss's H.264 / H.265 AHAT profiles: the AB code, the picture packings, recordings written with
// libx264 / libx265 and read back (in order and by seeking), and every bad unit's message.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>

#include "tofnav/io/file.hpp"
#include "tofnav/io/io_error.hpp"
#include "tofnav/recording/hl2ss_format.hpp"
#include "tofnav/recording/hl2ss_recording.hpp"
#include "tofnav/recording/hl2ss_test_files.hpp"
#include "tofnav/recording/hl2ss_video_planes.hpp"

namespace tofnav {
namespace {

using hl2ss_test::TempPath;

/// A scene with what matters to tofnav: a smooth head-like range field (300-1000 mm), skin-level
/// AB and a bright retro-reflective disc that moves one pixel per frame.
AhatFrame SceneFrame(int index) {
  AhatFrame frame;
  frame.host_ticks = 1'000'000 + static_cast<std::uint64_t>(index) * 222'222;
  frame.sensor_ticks_ns = 5'000 + static_cast<std::uint64_t>(index);
  frame.range_mm = Image<std::uint16_t>(kAhatWidth, kAhatHeight);
  frame.ab = Image<std::uint16_t>(kAhatWidth, kAhatHeight);
  for (int v = 0; v < kAhatHeight; ++v) {
    for (int u = 0; u < kAhatWidth; ++u) {
      const double du = u - 256.0, dv = v - 256.0;
      frame.range_mm(u, v) = static_cast<std::uint16_t>(300.0 + 0.0025 * (du * du + dv * dv));
      const double mu = u - (200.0 + index), mv = v - 240.0;
      const bool marker = mu * mu + mv * mv < 64.0;
      frame.ab(u, v) = static_cast<std::uint16_t>(
          marker ? 40000.0 : 400.0 + 300.0 * std::cos(0.02 * u) * std::sin(0.015 * v));
    }
  }
  return frame;
}

std::filesystem::path WriteScene(const std::string& name, Hl2ssDepthProfile z, Hl2ssVideoProfile ab,
                                 int frames) {
  const auto path = TempPath(name);
  Hl2ssRecordingWriter writer(path, {.profile_z = z, .profile_ab = ab});
  for (int i = 0; i < frames; ++i) writer.Append(SceneFrame(i));
  writer.Close();
  return path;
}

std::vector<std::uint8_t> FileBytes(const std::filesystem::path& path) {
  return ReadFileBytes(path);
}

std::string ErrorOf(const std::function<void()>& action) {
  try {
    action();
  } catch (const IoError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(Hl2ssAbCode, EmulatesTheHalfFloatSquareRoot) {
  // Tolerance: none. docs/ahat.md 3.6.1: one above floor(sqrt(x)) for 3214 inputs, e.g. 1088.
  int above = 0;
  for (int x = 0; x < 65536; ++x) {
    const auto root = static_cast<int>(std::floor(std::sqrt(static_cast<double>(x))));
    const int code = Hl2ssAbCode(static_cast<std::uint16_t>(x));
    ASSERT_TRUE(code == root || code == root + 1) << x;
    above += code == root + 1 ? 1 : 0;
  }
  EXPECT_EQ(above, 3214);
  EXPECT_EQ(Hl2ssAbCode(1088), 33);
  EXPECT_EQ(Hl2ssAbCode(65535), 255);  // +inf saturates to 65535, low byte 255
  EXPECT_EQ(Hl2ssAbCode(0), 0);
}

TEST(Hl2ssStreamProfile, NamesRoundTripAndAliasesParse) {
  for (const Hl2ssDepthProfile z : {Hl2ssDepthProfile::kSame, Hl2ssDepthProfile::kZdepth}) {
    for (const Hl2ssVideoProfile ab :
         {Hl2ssVideoProfile::kRaw, Hl2ssVideoProfile::kH264Base, Hl2ssVideoProfile::kH264Main,
          Hl2ssVideoProfile::kH264High, Hl2ssVideoProfile::kH265Main}) {
      const Hl2ssStreamProfile profile{z, ab};
      EXPECT_EQ(ParseHl2ssStreamProfile(Hl2ssStreamProfileName(profile)), profile);
    }
  }
  EXPECT_EQ(Hl2ssStreamProfileName({Hl2ssDepthProfile::kZdepth, Hl2ssVideoProfile::kH265Main}),
            "zdepth+h265");
  EXPECT_EQ(ParseHl2ssStreamProfile("same+raw"),
            (Hl2ssStreamProfile{Hl2ssDepthProfile::kSame, Hl2ssVideoProfile::kRaw}));
  EXPECT_EQ(ParseHl2ssStreamProfile("zdepth+h264-main"),
            (Hl2ssStreamProfile{Hl2ssDepthProfile::kZdepth, Hl2ssVideoProfile::kH264Main}));
  EXPECT_FALSE(ParseHl2ssStreamProfile("zdepth+h266"));
  EXPECT_FALSE(ParseHl2ssStreamProfile("h265"));
}

TEST(Hl2ssPictures, SamePackingRoundTripsAsTheClientRecoversIt) {
  const AhatFrame frame = SceneFrame(0);
  Image<std::uint16_t> range = frame.range_mm;
  range(0, 0) = 1030;  // wraps: code 1 -> 4 mm
  range(1, 0) = 4093;  // invalid -> 0
  Image<std::uint16_t> range_out, ab_out;
  UnpackHl2ssSamePicture(PackHl2ssSamePicture(range, frame.ab), range_out, ab_out);
  EXPECT_EQ(range_out(0, 0), 4);
  EXPECT_EQ(range_out(1, 0), 0);
  for (int v = 0; v < kAhatHeight; v += 7) {
    for (int u = 2; u < kAhatWidth; u += 5) {
      EXPECT_EQ(range_out(u, v), 4 * (range(u, v) / 4)) << u << "," << v;
      const int code = Hl2ssAbCode(frame.ab(u - u % 2, v));
      ASSERT_EQ(ab_out(u, v), code * code) << u << "," << v;
    }
  }
  // The chroma layout of docs/ahat.md 3.6.2: U(j, k) holds AB row 2k + j / 128, column 4 (j % 128).
  const Yuv420Picture picture = PackHl2ssSamePicture(range, frame.ab);
  EXPECT_EQ(picture.u(130, 3), Hl2ssAbCode(frame.ab(4 * 2, 2 * 3 + 1)));
  EXPECT_EQ(picture.v(5, 10), Hl2ssAbCode(frame.ab(4 * 5 + 2, 20)));
}

struct ProfileCase {
  Hl2ssDepthProfile z;
  Hl2ssVideoProfile ab;
  const char* name;
};

class Hl2ssVideoRecording : public ::testing::TestWithParam<ProfileCase> {};

TEST_P(Hl2ssVideoRecording, WritesAndReadsTheHeadsetStream) {
  const ProfileCase p = GetParam();
  const auto path = WriteScene("scene.bin", p.z, p.ab, 50);
  const Hl2ssRecording recording(path);
  EXPECT_EQ(recording.format(), std::string("hl2ss ") + p.name);
  EXPECT_EQ(recording.config().bitrate_bps, Hl2ssDefaultAhatBitrate(p.z, p.ab));
  EXPECT_EQ(Hl2ssGopFrames(recording.config()), 45);
  ASSERT_EQ(recording.frame_count(), 50u);
  EXPECT_TRUE(recording.key_frame(0));
  EXPECT_FALSE(recording.key_frame(1));
  EXPECT_TRUE(recording.key_frame(45));
  EXPECT_EQ(recording.measured_gop_frames(), 45);
  // Rate control: tolerance 2x, the encoder undershoots on this smooth scene and overshoots on
  // the first key frame; the hl2ss defaults differ 16-fold between SAME and ZDEPTH.
  EXPECT_LT(recording.ab_bitrate_bps(), 2.0 * recording.config().bitrate_bps);

  const bool same = p.z == Hl2ssDepthProfile::kSame;
  std::vector<AhatFrame> in_order;
  for (std::size_t i = 0; i < recording.frame_count(); ++i)
    in_order.push_back(recording.ReadFrame(i));
  for (const std::size_t i : {std::size_t{47}, std::size_t{3}, std::size_t{44}, std::size_t{45}}) {
    const AhatFrame again = recording.ReadFrame(i);  // seeks through the key frames
    EXPECT_EQ(again.range_mm, in_order[i].range_mm) << i;
    EXPECT_EQ(again.ab, in_order[i].ab) << i;
  }
  // Read ahead (two frame threads) and as a live stream decodes (one): the same frames bit for
  // bit (tolerance: none; libavcodec's frame threads decode exactly what one thread does).
  Hl2ssVideoDecoder live(recording.config());
  for (std::size_t i = 0; i < recording.frame_count(); ++i) {
    const AhatFrame one = recording.ReadFrameWith(i, live);
    ASSERT_EQ(one.range_mm, in_order[i].range_mm) << i;
    ASSERT_EQ(one.ab, in_order[i].ab) << i;
  }
  const AhatFrame truth = SceneFrame(30);
  const AhatFrame& frame = in_order[30];
  EXPECT_EQ(frame.host_ticks, truth.host_ticks);
  EXPECT_EQ(frame.sensor_ticks_ns, truth.sensor_ticks_ns);
  EXPECT_TRUE(frame.ab_lossy);
  EXPECT_EQ(frame.ab_half_res, same);
  EXPECT_EQ(frame.depth_step_mm, same ? 4.0 : 2.0);
  // Depth: exact through Zdepth at 201-749 mm; SAME within its 4 mm step plus codec noise
  // (median within one step: a lossy codec at the hl2ss default bitrate).
  std::vector<double> depth_error, code_error;
  for (int v = 100; v < 400; v += 3) {
    for (int u = 100; u < 400; u += 3) {
      const double d = std::abs(static_cast<double>(frame.range_mm(u, v)) - truth.range_mm(u, v));
      depth_error.push_back(d);
      if (!same && truth.range_mm(u, v) < 750) {
        ASSERT_EQ(d, 0.0) << u << "," << v;
      }
      code_error.push_back(std::abs(std::sqrt(static_cast<double>(frame.ab(u, v))) -
                                    Hl2ssAbCode(truth.ab(u - (same ? u % 2 : 0), v))));
    }
  }
  std::nth_element(depth_error.begin(), depth_error.begin() + depth_error.size() / 2,
                   depth_error.end());
  std::nth_element(code_error.begin(), code_error.begin() + code_error.size() / 2,
                   code_error.end());
  EXPECT_LE(depth_error[depth_error.size() / 2], same ? 4.0 : 0.0);
  EXPECT_LE(code_error[code_error.size() / 2], 1.0);  // median AB code error: one code
  // The marker stays the brightest spot.
  EXPECT_GT(frame.ab(230, 240), 20000);
}

INSTANTIATE_TEST_SUITE_P(
    Profiles, Hl2ssVideoRecording,
    ::testing::Values(
        ProfileCase{Hl2ssDepthProfile::kZdepth, Hl2ssVideoProfile::kH265Main, "ZDEPTH+H265_MAIN"},
        ProfileCase{Hl2ssDepthProfile::kSame, Hl2ssVideoProfile::kH265Main, "SAME+H265_MAIN"},
        ProfileCase{Hl2ssDepthProfile::kZdepth, Hl2ssVideoProfile::kH264Main, "ZDEPTH+H264_MAIN"},
        ProfileCase{Hl2ssDepthProfile::kSame, Hl2ssVideoProfile::kH264Base, "SAME+H264_BASE"},
        ProfileCase{Hl2ssDepthProfile::kZdepth, Hl2ssVideoProfile::kH264High, "ZDEPTH+H264_HIGH"}),
    [](const auto& test) {
      std::string name = test.param.name;
      std::replace(name.begin(), name.end(), '+', '_');
      return name;
    });

TEST(Hl2ssVideoStream, H264UnitsStartWithTheDelimiterThePythonClientCutsOff) {
  const auto path =
      WriteScene("h264.bin", Hl2ssDepthProfile::kZdepth, Hl2ssVideoProfile::kH264Main, 3);
  const Hl2ssRecording recording(path);
  const auto bytes = FileBytes(path);
  for (std::size_t i = 0; i < 3; ++i) {
    const std::uint64_t offset = recording.packet_offset(i);
    std::uint32_t size_z;
    std::memcpy(&size_z, bytes.data() + offset + 12, 4);
    const std::uint8_t* unit = bytes.data() + offset + 20 + size_z;
    EXPECT_EQ(std::vector<std::uint8_t>(unit, unit + 5), (std::vector<std::uint8_t>{0, 0, 0, 1, 9}))
        << i;
  }
}

// Bad input: each message checked word for word (docs/ahat.md 3.6.6).

struct UnitSpan {
  std::uint64_t offset;  // of the unit in the file
  std::uint32_t size;
};

UnitSpan UnitOf(const std::vector<std::uint8_t>& bytes, const Hl2ssRecording& recording,
                std::size_t index) {
  const std::uint64_t packet = recording.packet_offset(index);
  std::uint32_t size_z, size_ab;
  std::memcpy(&size_z, bytes.data() + packet + 12, 4);
  std::memcpy(&size_ab, bytes.data() + packet + 16, 4);
  return {packet + 20 + size_z, size_ab};
}

std::string Hl2ssErrorMessage(const std::vector<std::uint8_t>& bytes, std::size_t frame) {
  return ErrorOf([&] {
    const Hl2ssRecording recording(bytes, "bad.bin");
    for (std::size_t i = 0; i <= frame; ++i) recording.ReadFrame(i);
  });
}

TEST(Hl2ssVideoErrors, AStreamThatStartsWithoutAKeyFrame) {
  const auto path =
      WriteScene("nokey.bin", Hl2ssDepthProfile::kZdepth, Hl2ssVideoProfile::kH265Main, 4);
  auto bytes = FileBytes(path);
  const Hl2ssRecording recording(path);
  // Cut the first packet out: the file now starts with a P picture.
  const auto first = static_cast<std::ptrdiff_t>(recording.packet_offset(0));
  const auto second = static_cast<std::ptrdiff_t>(recording.packet_offset(1));
  bytes.erase(bytes.begin() + first, bytes.begin() + second);
  const Hl2ssRecording cut(bytes, "bad.bin");
  const UnitSpan unit = UnitOf(bytes, cut, 0);
  EXPECT_EQ(Hl2ssErrorMessage(bytes, 0),
            "bad.bin: at byte " + std::to_string(unit.offset) + ": frame 0: H.265 access unit of " +
                std::to_string(unit.size) +
                " bytes is not a key frame, and the decoder has none to start from (a stream "
                "must start with an IDR picture)");
}

TEST(Hl2ssVideoErrors, ACorruptUnitNamesTheFileOffsetAndFrame) {
  for (const auto ab : {Hl2ssVideoProfile::kH265Main, Hl2ssVideoProfile::kH264Main}) {
    const auto path = WriteScene("corrupt.bin", Hl2ssDepthProfile::kSame, ab, 3);
    auto bytes = FileBytes(path);
    const Hl2ssRecording recording(path);
    const UnitSpan unit = UnitOf(bytes, recording, 1);
    // Garbage after the first NAL header: CABAC decodes any bits, so damage must reach the
    // headers to be seen (no decoder can see every corruption without a checksum).
    for (std::uint32_t i = 6; i < unit.size; ++i) {
      bytes[unit.offset + i] = static_cast<std::uint8_t>(0xFF ^ (i * 37));
    }
    const std::string message = Hl2ssErrorMessage(bytes, 1);
    const std::string codec = ab == Hl2ssVideoProfile::kH265Main ? "H.265" : "H.264";
    EXPECT_THAT(message, ::testing::StartsWith("bad.bin: at byte " + std::to_string(unit.offset) +
                                               ": frame 1: " + codec + " access unit of " +
                                               std::to_string(unit.size) + " bytes "));
    EXPECT_THAT(message, ::testing::AnyOf(::testing::HasSubstr("does not decode: "),
                                          ::testing::HasSubstr("decodes to a damaged picture")));
  }
}

TEST(Hl2ssVideoErrors, ATruncatedUnit) {
  const auto path =
      WriteScene("short.bin", Hl2ssDepthProfile::kZdepth, Hl2ssVideoProfile::kH264Main, 2);
  auto bytes = FileBytes(path);
  const Hl2ssRecording recording(path);
  const UnitSpan unit = UnitOf(bytes, recording, 0);
  // Keep the packet framing consistent but drop the unit's last half (a cut-off access unit).
  const std::uint32_t kept = unit.size / 2;
  bytes.erase(bytes.begin() + static_cast<std::ptrdiff_t>(unit.offset + kept),
              bytes.begin() + static_cast<std::ptrdiff_t>(unit.offset + unit.size));
  const std::uint64_t packet = recording.packet_offset(0);
  std::uint32_t payload;
  std::memcpy(&payload, bytes.data() + packet + 8, 4);
  payload -= unit.size - kept;
  std::memcpy(bytes.data() + packet + 8, &payload, 4);
  std::memcpy(bytes.data() + packet + 16, &kept, 4);
  const std::string message = Hl2ssErrorMessage(bytes, 0);
  EXPECT_THAT(message, ::testing::StartsWith("bad.bin: at byte " + std::to_string(unit.offset) +
                                             ": frame 0: H.264 access unit of " +
                                             std::to_string(kept) + " bytes "));
}

TEST(Hl2ssVideoErrors, AProfileChangeInTheMiddleOfAFile) {
  // An H.265 file whose third packet carries an H.264 unit (another profile's stream appended).
  const auto h265 =
      WriteScene("h265.bin", Hl2ssDepthProfile::kSame, Hl2ssVideoProfile::kH265Main, 2);
  const auto h264 =
      WriteScene("h264.bin", Hl2ssDepthProfile::kSame, Hl2ssVideoProfile::kH264Main, 1);
  auto bytes = FileBytes(h265);
  const auto other = FileBytes(h264);
  const Hl2ssRecording other_recording(h264);
  bytes.insert(bytes.end(),
               other.begin() + static_cast<std::ptrdiff_t>(other_recording.packet_offset(0)),
               other.end());
  // The appended packet's timestamp is earlier than the file's: make it later.
  const std::uint64_t appended = FileBytes(h265).size();
  const std::uint64_t later = 9'000'000;
  std::memcpy(bytes.data() + appended, &later, 8);
  const Hl2ssRecording joined(bytes, "bad.bin");
  ASSERT_EQ(joined.frame_count(), 3u);
  const UnitSpan unit = UnitOf(bytes, joined, 2);
  const std::string message = Hl2ssErrorMessage(bytes, 2);
  EXPECT_THAT(message, ::testing::StartsWith("bad.bin: at byte " + std::to_string(unit.offset) +
                                             ": frame 2: H.265 access unit of " +
                                             std::to_string(unit.size) + " bytes "));
}

}  // namespace
}  // namespace tofnav
