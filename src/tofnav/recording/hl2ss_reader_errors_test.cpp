// SPDX-License-Identifier: BSD-3-Clause
// Malformed hl2ss AHAT files: every failure is an IoError at the right byte; truncated tails drop.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <functional>

#include "tofnav/core/require.hpp"
#include "tofnav/io/file.hpp"
#include "tofnav/io/io_error.hpp"
#include "tofnav/recording/hl2ss_recording.hpp"
#include "tofnav/recording/hl2ss_test_files.hpp"

namespace tofnav {
namespace {

using namespace hl2ss_test;  // NOLINT(google-build-using-namespace): test helpers
using ::testing::HasSubstr;

constexpr std::uint64_t kFirstPacket = kHeaderBytes;
constexpr std::uint64_t kFramePacketBytes = 12 + 16 + 2 * kRawPlane + 64;
constexpr std::uint64_t kEmptyPacket = kFirstPacket + kFramePacketBytes;
constexpr std::uint64_t kSecondFramePacket = kEmptyPacket + 12 + 16 + 64;

void Poke32(std::vector<std::uint8_t>& bytes, std::uint64_t offset, std::uint32_t value) {
  for (int i = 0; i < 4; ++i) bytes.at(offset + i) = static_cast<std::uint8_t>(value >> (8 * i));
}

void ExpectIoError(const std::vector<std::uint8_t>& bytes, std::uint64_t offset,
                   const std::string& text) {
  try {
    const Hl2ssRecording recording(bytes, "corrupt.bin");
    FAIL() << "opened without error";
  } catch (const IoError& e) {
    EXPECT_EQ(e.offset(), offset) << e.what();
    EXPECT_THAT(e.what(), HasSubstr("corrupt.bin"));
    EXPECT_THAT(e.what(), HasSubstr(text));
  }
}

TEST(Hl2ssRecordingErrors, BadMagic) {
  auto bytes = CurrentSameRawMode1().data;
  bytes[7] = '4';
  ExpectIoError(bytes, 0, "HL2SSV23");
  std::copy_n("V02HL2SS", 8, bytes.begin());
  ExpectIoError(bytes, 0, "older hl2ss");
}

TEST(Hl2ssRecordingErrors, WrongPortNamesThePort) {
  ExpectIoError(Header(1, 0, 3805).data, 8, "port 3805");
}

TEST(Hl2ssRecordingErrors, TruncatedHeader) {
  const auto whole = Header(1).data;
  for (const std::uint64_t size : {std::uint64_t{5}, std::uint64_t{20}, kHeaderBytes - 3}) {
    ExpectIoError({whole.begin(), whole.begin() + static_cast<std::ptrdiff_t>(size)}, size,
                  "expected");
  }
  auto bytes = whole;
  Poke32(bytes, 10, 1'000'000'000);  // user_len
  ExpectIoError(bytes, 10, "user_len");
}

TEST(Hl2ssRecordingErrors, BadConfigFields) {
  auto bytes = Header(2).data;  // mode 2 is live calibration only
  ExpectIoError(bytes, 20, "mode");
  bytes = Header(1, 0, 3804, 7).data;
  ExpectIoError(bytes, 23, "profile_ab");
}

TEST(Hl2ssRecordingErrors, PayloadSizeBeyondEndInTheMiddle) {
  auto bytes = CurrentSameRawMode1().data;
  Poke32(bytes, kFirstPacket + 8, 0x7FFFFFF0);
  ExpectIoError(bytes, kFirstPacket + 8, "payload_size 2147483632");
  Poke32(bytes, kFirstPacket + 8, 2 * kRawPlane + 12);  // fits no layout
  ExpectIoError(bytes, kFirstPacket + 8, "matches no AHAT payload layout");
}

TEST(Hl2ssRecordingErrors, CorruptSizeFields) {
  auto bytes = CurrentSameRawMode1().data;
  Poke32(bytes, kSecondFramePacket + 12, 1);  // size_z 1 + size_ab 1048575: sums right
  Poke32(bytes, kSecondFramePacket + 16, 2 * kRawPlane - 1);
  ExpectIoError(bytes, kSecondFramePacket + 12, "size_z must be 0");
  bytes = CurrentSameRawMode1().data;
  Poke32(bytes, kSecondFramePacket + 8, 16 + kRawPlane);  // consistent, but not a RAW blob
  Poke32(bytes, kSecondFramePacket + 16, kRawPlane);
  ExpectIoError(bytes, kSecondFramePacket + 16, "size_ab must be 1048576");
}

TEST(Hl2ssRecordingErrors, ZdepthPayloadWithoutSizes) {
  Bytes b = Header(0, 1);
  b.Put<std::uint64_t>(1).Put<std::uint32_t>(20).Append(std::vector<std::uint8_t>(20, 0xAB));
  ExpectIoError(b.data, kFirstPacket + 8, "matches no AHAT payload layout");
}

TEST(Hl2ssRecordingErrors, DecreasingTimestamp) {
  auto bytes = CurrentSameRawMode1().data;
  Poke32(bytes, kSecondFramePacket, 900);
  ExpectIoError(bytes, kSecondFramePacket, "earlier than the previous frame's 1000");
}

TEST(Hl2ssRecordingErrors, TruncatedTailIsDropped) {
  const auto whole = CurrentSameRawMode1().data;
  const std::uint64_t cuts[] = {kSecondFramePacket + 5, kSecondFramePacket + 18,
                                kSecondFramePacket + 12 + 16 + 1000, whole.size() - 1};
  for (const std::uint64_t cut : cuts) {
    const Hl2ssRecording recording(
        {whole.begin(), whole.begin() + static_cast<std::ptrdiff_t>(cut)}, "cut.bin");
    EXPECT_TRUE(recording.truncated_tail()) << cut;
    ASSERT_EQ(recording.frame_count(), 1u) << cut;
    EXPECT_EQ(recording.ReadFrame(0).host_ticks, 1000u);
  }
  const Hl2ssRecording exact(
      {whole.begin(), whole.begin() + static_cast<std::ptrdiff_t>(kSecondFramePacket)}, "cut.bin");
  EXPECT_FALSE(exact.truncated_tail());
  EXPECT_EQ(exact.frame_count(), 1u);
  EXPECT_EQ(exact.skipped_empty_packets(), 1u);
}

TEST(Hl2ssRecordingErrors, NonRigidPoseAtItsOffset) {
  auto bytes = CurrentSameRawMode1().data;
  const std::uint64_t pose = kFirstPacket + 12 + 16 + 2 * kRawPlane;
  Poke32(bytes, pose + 4, 0x40000000);  // m12 = 2.0: the rotation block is no longer orthonormal
  const Hl2ssRecording recording(bytes, "pose.bin");
  try {
    recording.ReadFrame(0);
    FAIL();
  } catch (const IoError& e) {
    EXPECT_EQ(e.offset(), pose);
    EXPECT_THAT(e.what(), HasSubstr("rigid"));
  }
  EXPECT_NO_THROW(recording.ReadFrame(1));
  EXPECT_THROW(recording.ReadFrame(2), PreconditionError);
}

TEST(Hl2ssRecordingErrors, LegacyH26xPayloadIsOneAccessUnit) {
  Bytes b = Header(0, 0, 3804, 3);  // SAME + H265_MAIN, legacy: the payload is one access unit
  b.Put<std::uint64_t>(7).Put<std::uint32_t>(6).Append({0, 0, 0, 1, 0x40, 0x01});  // a VPS only
  const Hl2ssRecording recording(b.data, "h265.bin");
  EXPECT_EQ(recording.format(), "hl2ss SAME+H265_MAIN");
  ASSERT_EQ(recording.frame_count(), 1u);
  EXPECT_EQ(recording.layout(0), Hl2ssPayloadLayout::kLegacySame);
  try {
    recording.ReadFrame(0);
    FAIL();
  } catch (const IoError& e) {
    EXPECT_EQ(e.offset(), kFirstPacket + 12);  // the unit right after the packet header
    EXPECT_THAT(e.what(), HasSubstr("frame 0: H.265 access unit of 6 bytes is not a key frame"));
  }
}

TEST(Hl2ssRecordingErrors, CorruptZdepthStreamAtItsFileOffset) {
  const auto path = TempPath("zdepth.bin");
  Hl2ssWriterOptions options;
  options.profile_z = Hl2ssDepthProfile::kZdepth;
  options.mode = 0;
  AhatFrame frame;
  frame.range_mm = Image<std::uint16_t>(512, 512, 500);
  frame.ab = Image<std::uint16_t>(512, 512, 7);
  Hl2ssRecordingWriter writer(path, options);
  writer.Append(frame);
  writer.Close();
  auto bytes = ReadFileBytes(path);
  const std::uint64_t stream = 8 + 2 + 4 + options.user.size() + 10 + 16 + 12 + 8;
  ASSERT_EQ(bytes[stream], 0xCA);  // Zdepth magic (docs/ahat.md 4.1)
  bytes[stream] = 0xCB;
  const Hl2ssRecording recording(bytes, "zdepth.bin");
  ASSERT_EQ(recording.frame_count(), 1u);
  try {
    recording.ReadFrame(0);
    FAIL();
  } catch (const IoError& e) {
    EXPECT_EQ(e.offset(), stream) << e.what();
  }
}

TEST(Hl2ssRecordingErrors, MissingFileIsIoError) {
  EXPECT_THROW(OpenHl2ssRecording(TempPath("absent.bin")), IoError);
}

}  // namespace
}  // namespace tofnav
