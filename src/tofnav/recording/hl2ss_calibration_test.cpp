// SPDX-License-Identifier: BSD-3-Clause
// hl2ss calibration folder and Mode-2 blob: layouts, lossless round trips, sample-offset rule.
#include "tofnav/recording/hl2ss_calibration.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>

#include "matchers.hpp"
#include "tofnav/core/require.hpp"
#include "tofnav/io/file.hpp"
#include "tofnav/io/io_error.hpp"
#include "tofnav/recording/hl2ss_test_files.hpp"

namespace tofnav {
namespace {

using hl2ss_test::TempPath;
using ::testing::HasSubstr;

constexpr double kExtrinsicRotTolRad = 1e-6;   // f32 rotation entries: ~1e-7 rounding
constexpr double kExtrinsicTransTolMm = 1e-4;  // f32 metres at ~6 cm: 4e-6 mm per ulp
constexpr std::size_t kPixels = 512 * 512;

/// A hand-made calibration: equidistant fisheye table (f = 254 px), one NaN entry, an analytic
/// undistort map, the measured device's pinhole and a rotated, shifted extrinsic.
AhatCalibration HandMadeCalibration(double fx = 114.14, double fy = 114.84) {
  static const AhatCalibration base = [] {  // built once: 2 x 262144 entries in a debug build
    AhatCalibration c;
    c.uv2xy = Image<Eigen::Vector2f>(512, 512, Eigen::Vector2f::Zero());
    c.undistort_map = Image<Eigen::Vector2f>(512, 512, Eigen::Vector2f::Zero());
    Eigen::Vector2f* table = c.uv2xy.data();
    Eigen::Vector2f* map = c.undistort_map.data();
    for (int v = 0; v < 512; ++v) {
      for (int u = 0; u < 512; ++u, ++table, ++map) {
        const double dx = u + 0.5 - 252.4;
        const double dy = v + 0.5 - 252.8;
        const double r = std::max(std::hypot(dx, dy), 1e-9);
        const double scale = std::tan(r / 254.0) / r;
        (*table)[0] = static_cast<float>(scale * dx);
        (*table)[1] = static_cast<float>(scale * dy);
        (*map)[0] = 0.5f * static_cast<float>(u) + 128.25f;
        (*map)[1] = 0.75f * static_cast<float>(v) + 64.5f;
      }
    }
    c.uv2xy(7, 9) = Eigen::Vector2f(std::numeric_limits<float>::quiet_NaN(), 0.0f);
    c.rig_from_ahat = Rigid3d(
        Eigen::Quaterniond(Eigen::AngleAxisd(1.3, Eigen::Vector3d(0.3, -1, 0.2).normalized())),
        Eigen::Vector3d(21.2, -59.2, 11.8));
    c.scale = 1000.0;
    c.alias_mm = 1055.0;
    return c;
  }();
  AhatCalibration c = base;
  c.pinhole_fx_fy_cx_cy = {fx, fy, 252.61, 256.84};
  return c;
}

bool SameBits(const Image<Eigen::Vector2f>& a, const Image<Eigen::Vector2f>& b) {
  return a.width() == b.width() && a.height() == b.height() &&
         std::memcmp(a.data(), b.data(), a.size() * sizeof(Eigen::Vector2f)) == 0;
}

void ExpectSameCalibration(const AhatCalibration& read, const AhatCalibration& written) {
  EXPECT_TRUE(SameBits(read.uv2xy, written.uv2xy));
  EXPECT_TRUE(SameBits(read.undistort_map, written.undistort_map));
  for (int i = 0; i < 4; ++i) {
    EXPECT_EQ(read.pinhole_fx_fy_cx_cy[i],
              static_cast<double>(static_cast<float>(written.pinhole_fx_fy_cx_cy[i])));
  }
  EXPECT_EQ(read.scale, written.scale);
  EXPECT_EQ(read.alias_mm, written.alias_mm);
  EXPECT_THAT(read.rig_from_ahat,
              RigidNear(written.rig_from_ahat, kExtrinsicRotTolRad, kExtrinsicTransTolMm));
}

std::vector<float> FloatsOf(const std::vector<std::uint8_t>& bytes) {
  std::vector<float> floats(bytes.size() / 4);
  std::memcpy(floats.data(), bytes.data(), floats.size() * 4);
  return floats;
}

TEST(Hl2ssCalibration, FolderRoundTripAndLayout) {
  const AhatCalibration written = HandMadeCalibration();
  const auto root = TempPath("calib");
  WriteHl2ssCalibration(root, written);
  const auto folder = root / "rm_depth_ahat";
  EXPECT_EQ(std::filesystem::file_size(folder / "uv2xy.bin"), 2'097'152u);
  EXPECT_EQ(std::filesystem::file_size(folder / "undistort_map.bin"), 2'097'152u);
  EXPECT_EQ(std::filesystem::file_size(folder / "scale.bin"), 4u);
  // uv2xy interleaved [v][u][x, y].
  const auto uv2xy = FloatsOf(ReadFileBytes(folder / "uv2xy.bin"));
  EXPECT_EQ(uv2xy[2 * (300 * 512 + 100) + 1], written.uv2xy(100, 300).y());
  // Extrinsics: rig -> camera, row-vector: rows of R^T, then the translation in metres.
  const auto e = FloatsOf(ReadFileBytes(folder / "extrinsics.bin"));
  const Rigid3d ahat_from_rig = written.rig_from_ahat.Inverse();
  const Eigen::Matrix3d r = ahat_from_rig.RotationMatrix();
  EXPECT_FLOAT_EQ(e[1], static_cast<float>(r(1, 0)));  // M[0][1] = R(1, 0)
  EXPECT_FLOAT_EQ(e[13], static_cast<float>(ahat_from_rig.translation.y() / 1000.0));
  EXPECT_EQ(e[15], 1.0f);
  const auto k = FloatsOf(ReadFileBytes(folder / "intrinsics.bin"));
  EXPECT_EQ(k, (std::vector<float>{114.14f, 0, 0, 0, 0, 114.84f, 0, 0, 252.61f, 256.84f, 1, 0, 0, 0,
                                   0, 1}));

  const AhatCalibration from_root = ReadHl2ssCalibration(root);
  ExpectSameCalibration(from_root, written);
  EXPECT_EQ(from_root.sample_offset_px, 0.5);                    // fx != fy: hl2ss <= v1.0.36
  ExpectSameCalibration(ReadHl2ssCalibration(folder), written);  // the folder itself
}

TEST(Hl2ssCalibration, SampleOffsetAutoRuleAndOverride) {
  const auto square = TempPath("square");
  WriteHl2ssCalibration(square, HandMadeCalibration(200.0, 200.0));
  EXPECT_EQ(ReadHl2ssCalibration(square).sample_offset_px, 0.0);  // fx == fy: >= v1.0.37
  EXPECT_EQ(ReadHl2ssCalibration(square, 0.5).sample_offset_px, 0.5);
  const auto blob = EncodeHl2ssMode2(HandMadeCalibration());
  EXPECT_EQ(DecodeHl2ssMode2(blob).sample_offset_px, 0.5);
  EXPECT_EQ(DecodeHl2ssMode2(blob, "blob", 0.0).sample_offset_px, 0.0);
  EXPECT_THROW(DecodeHl2ssMode2(blob, "blob", 0.25), PreconditionError);
}

TEST(Hl2ssCalibration, Mode2RoundTripAndPlanarLayout) {
  const AhatCalibration written = HandMadeCalibration();
  const auto blob = EncodeHl2ssMode2(written);
  ASSERT_EQ(blob.size(), kHl2ssMode2Bytes);
  const auto floats = FloatsOf(blob);
  EXPECT_EQ(floats[300 * 512 + 100], written.uv2xy(100, 300).x());            // uv2x plane
  EXPECT_EQ(floats[kPixels + 300 * 512 + 100], written.uv2xy(100, 300).y());  // uv2y plane
  EXPECT_EQ(floats[2 * kPixels + 15], 1.0f);                                  // extrinsics m44
  EXPECT_EQ(floats[2 * kPixels + 16], 1000.0f);                               // scale
  EXPECT_EQ(floats[2 * kPixels + 17], 1055.0f);                               // alias
  EXPECT_EQ(floats[3 * kPixels + 18 + 5], written.undistort_map(5, 0).y());   // mapy plane
  EXPECT_EQ(floats[4 * kPixels + 18], 114.14f);                               // fx
  EXPECT_EQ(floats[4 * kPixels + 21], 256.84f);                               // cy
  ExpectSameCalibration(DecodeHl2ssMode2(blob), written);
}

TEST(Hl2ssCalibration, FolderAndMode2ConvertLosslessly) {
  const auto first = TempPath("first");
  WriteHl2ssCalibration(first, HandMadeCalibration());
  // Byte-level conversion: folder -> Mode 2 -> folder gives every file back bit for bit.
  const auto blob = ReadHl2ssCalibrationAsMode2(first);
  ASSERT_EQ(blob.size(), kHl2ssMode2Bytes);
  const auto second = TempPath("second");
  WriteHl2ssMode2AsFolder(second, blob);
  for (const char* name : {"uv2xy.bin", "undistort_map.bin", "extrinsics.bin", "intrinsics.bin",
                           "scale.bin", "alias.bin"}) {
    EXPECT_TRUE(ReadFileBytes(first / "rm_depth_ahat" / name) ==
                ReadFileBytes(second / "rm_depth_ahat" / name))
        << name;
  }
  EXPECT_TRUE(ReadHl2ssCalibrationAsMode2(second / "rm_depth_ahat") == blob);
  // Through AhatCalibration: the tables stay bitwise, the extrinsics within f32 rounding.
  ExpectSameCalibration(DecodeHl2ssMode2(blob), ReadHl2ssCalibration(first));
  const auto third = TempPath("third");
  WriteHl2ssCalibration(third, DecodeHl2ssMode2(blob));
  EXPECT_TRUE(ReadFileBytes(first / "rm_depth_ahat" / "uv2xy.bin") ==
              ReadFileBytes(third / "rm_depth_ahat" / "uv2xy.bin"));
}

TEST(Hl2ssCalibration, WrongSizesAreIoErrors) {
  const auto root = TempPath("calib");
  WriteHl2ssCalibration(root, HandMadeCalibration());
  const auto uv2xy = root / "rm_depth_ahat" / "uv2xy.bin";
  WriteFileAtomically(uv2xy, std::vector<std::uint8_t>(1000));
  try {
    ReadHl2ssCalibration(root);
    FAIL();
  } catch (const IoError& e) {
    EXPECT_THAT(e.what(), HasSubstr("uv2xy.bin"));
    EXPECT_THAT(e.what(), HasSubstr("2097152"));
  }
  const std::vector<std::uint8_t> short_blob(kHl2ssMode2Bytes - 4);
  EXPECT_THROW(DecodeHl2ssMode2(short_blob), IoError);
  EXPECT_THROW(ReadHl2ssCalibration(TempPath("empty")), IoError);
}

TEST(Hl2ssCalibration, NonRigidExtrinsicsNameTheFile) {
  const auto root = TempPath("calib");
  WriteHl2ssCalibration(root, HandMadeCalibration());
  std::vector<std::uint8_t> bad(64, 0);  // all zeros: not a rigid transform
  WriteFileAtomically(root / "rm_depth_ahat" / "extrinsics.bin", bad);
  try {
    ReadHl2ssCalibration(root);
    FAIL();
  } catch (const IoError& e) {
    EXPECT_THAT(e.what(), HasSubstr("extrinsics.bin"));
    EXPECT_EQ(e.offset(), 0u);
  }
}

}  // namespace
}  // namespace tofnav
