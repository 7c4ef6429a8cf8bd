// SPDX-License-Identifier: BSD-3-Clause
// StreamRecorder LUT and transposed text matrices against hand-written files.
#include "tofnav/recording/stream_recorder_files.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <functional>
#include <numbers>
#include <sstream>

#include "matchers.hpp"
#include "tofnav/io/io_error.hpp"

namespace tofnav {
namespace {

// Text matrices printed with 9 significant digits round-trip to ~1e-9 relative.
constexpr double kNineDigitRotTolRad = 1e-7;
constexpr double kNineDigitTransTolMm = 1e-5;  // translations of a few metres
// The recorder's 6 significant digits: entries rounded by <= 5e-7 relative.
constexpr double kSixDigitRotTolRad = 1e-5;
constexpr double kSixDigitTransTolMm = 1e-3;
// f32 unit ray -> (x / z, y / z) -> f32: a few float ulps, relative.
constexpr double kLutRelTol = 1e-6;

std::uint64_t ErrorOffset(const std::function<void()>& f, std::string* message = nullptr) {
  try {
    f();
  } catch (const IoError& error) {
    if (message != nullptr) *message = error.what();
    return error.offset().value_or(~std::uint64_t{0});
  }
  ADD_FAILURE() << "no IoError";
  return 0;
}

Rigid3d RotZ(double angle_rad, const Eigen::Vector3d& translation_mm) {
  return {Eigen::Quaterniond(Eigen::AngleAxisd(angle_rad, Eigen::Vector3d::UnitZ())),
          translation_mm};
}

void PutFloat(std::vector<std::uint8_t>& lut, std::size_t index, float value) {
  std::memcpy(lut.data() + index * 4, &value, 4);  // the test host is little-endian
}

TEST(StreamRecorderLut, DecodesHandWrittenRays) {
  std::vector<std::uint8_t> lut(kStreamRecorderLutBytes, 0);  // all z = 0: invalid
  const auto set = [&lut](int u, int v, float x, float y, float z) {
    const std::size_t pixel = static_cast<std::size_t>(v) * 512 + static_cast<std::size_t>(u);
    PutFloat(lut, pixel * 3, x);
    PutFloat(lut, pixel * 3 + 1, y);
    PutFloat(lut, pixel * 3 + 2, z);
  };
  set(10, 20, 0.6F, 0.0F, 0.8F);         // (0.75, 0)
  set(511, 0, -0.48F, 0.6F, 0.64F);      // (-0.75, 0.9375)
  set(5, 5, 0.3F, 0.4F, 0.0F);           // z == 0: a failed API call, stale x, y
  set(6, 5, 0.3F, 0.4F, -0.5F);          // behind the camera
  set(7, 5, std::nanf(""), 0.0F, 1.0F);  // not finite
  const Image<Eigen::Vector2f> uv2xy = DecodeStreamRecorderLut(lut, "lut.bin");
  EXPECT_NEAR(uv2xy(10, 20).x(), 0.75, kLutRelTol);
  EXPECT_NEAR(uv2xy(10, 20).y(), 0.0, kLutRelTol);
  EXPECT_NEAR(uv2xy(511, 0).x(), -0.75, kLutRelTol);
  EXPECT_NEAR(uv2xy(511, 0).y(), 0.9375, kLutRelTol);
  EXPECT_TRUE(std::isnan(uv2xy(5, 5).x()));
  EXPECT_TRUE(std::isnan(uv2xy(6, 5).y()));
  EXPECT_TRUE(std::isnan(uv2xy(7, 5).x()));
  EXPECT_TRUE(std::isnan(uv2xy(0, 0).x()));

  lut.pop_back();
  EXPECT_EQ(ErrorOffset([&] { DecodeStreamRecorderLut(lut, "lut.bin"); }),
            kStreamRecorderLutBytes - 1);
}

TEST(StreamRecorderLut, EncodeDecodeRoundTrip) {
  Image<Eigen::Vector2f> uv2xy(512, 512, Eigen::Vector2f::Zero());
  for (int v = 0; v < 512; ++v) {
    for (int u = 0; u < 512; ++u) {
      uv2xy(u, v) = Eigen::Vector2f(static_cast<float>((u - 252.4) / 254.0),
                                    static_cast<float>((v - 252.8) / 254.0));
    }
  }
  uv2xy(0, 0) = Eigen::Vector2f::Constant(std::nanf(""));
  const std::vector<std::uint8_t> bytes = EncodeStreamRecorderLut(uv2xy);
  float z00 = 1.0F;
  std::memcpy(&z00, bytes.data() + 8, 4);
  EXPECT_EQ(z00, 0.0F);  // invalid entries are written with z = 0, as the recorder does
  const Image<Eigen::Vector2f> decoded = DecodeStreamRecorderLut(bytes, "lut.bin");
  EXPECT_TRUE(std::isnan(decoded(0, 0).x()));
  double worst = 0.0;
  for (int v = 1; v < 512; v += 3) {  // every third row keeps the unoptimised test quick
    for (int u = 0; u < 512; ++u) {
      const double scale = std::max(1.0, static_cast<double>(uv2xy(u, v).norm()));
      worst = std::max(worst, static_cast<double>((decoded(u, v) - uv2xy(u, v)).norm()) / scale);
    }
  }
  EXPECT_LT(worst, kLutRelTol);
}

TEST(StreamRecorderExtrinsics, HandWrittenLineIsRigToCameraInMetres) {
  // Column-vector ahat_from_rig: 90 degrees about z, translation (0.01, -0.02, 0.03) m.
  const std::string text = "0,-1,0,0.01,1,0,0,-0.02,0,0,1,0.03,0,0,0,1\r\n";
  const Rigid3d rig_from_ahat = ParseStreamRecorderExtrinsics(text, "ext.txt");
  // Inverse: -90 degrees about z, translation -R^T t = -(-20, -10, 30) mm.
  EXPECT_THAT(rig_from_ahat, RigidNear(RotZ(-std::numbers::pi / 2, {20.0, 10.0, -30.0}),
                                       kNineDigitRotTolRad, kNineDigitTransTolMm));
}

TEST(StreamRecorderExtrinsics, AcceptsTheRecordersSixDigitsAndRoundTripsNine) {
  const Rigid3d truth{Eigen::Quaterniond(0.3, -0.5, 0.7, 0.2), {21.2, -59.2, 11.8}};
  const Eigen::Matrix4d ahat_from_rig = truth.Inverse().ToMatrix();
  std::ostringstream six_digits;  // default iostream precision, as the recorder prints
  for (int i = 0; i < 16; ++i) {
    const double value = ahat_from_rig(i / 4, i % 4) / (i % 4 == 3 && i < 12 ? 1000.0 : 1.0);
    six_digits << (i > 0 ? "," : "") << value;
  }
  EXPECT_THAT(ParseStreamRecorderExtrinsics(six_digits.str() + "\n", "ext.txt"),
              RigidNear(truth, kSixDigitRotTolRad, kSixDigitTransTolMm));
  EXPECT_THAT(ParseStreamRecorderExtrinsics(FormatStreamRecorderExtrinsics(truth), "ext.txt"),
              RigidNear(truth, kNineDigitRotTolRad, kNineDigitTransTolMm));
}

TEST(StreamRecorderExtrinsics, MalformedTextIsAnErrorAtTheLine) {
  const std::string identity = "1,0,0,0,0,1,0,0,0,0,1,0,0,0,0,1";
  std::string message;
  EXPECT_EQ(ErrorOffset([&] { ParseStreamRecorderExtrinsics("1,0,0", "ext.txt"); }, &message), 0U);
  EXPECT_NE(message.find("ext.txt"), std::string::npos) << message;
  EXPECT_EQ(ErrorOffset([&] { ParseStreamRecorderExtrinsics("", "ext.txt"); }), 0U);
  EXPECT_EQ(ErrorOffset([&] {
              ParseStreamRecorderExtrinsics(identity + "\n" + identity + "\n", "ext.txt");
            }),
            identity.size() + 1);  // the second line
  EXPECT_EQ(
      ErrorOffset(
          [&] { ParseStreamRecorderExtrinsics("\n1,0,0,0,0,1,0,0,0,0,1,0,0,0,0,x", "ext.txt"); },
          &message),
      1U);
  EXPECT_NE(message.find("field 16"), std::string::npos) << message;
  EXPECT_EQ(ErrorOffset([&] {  // scaled by 2: not rigid
              ParseStreamRecorderExtrinsics("2,0,0,0,0,2,0,0,0,0,2,0,0,0,0,1", "ext.txt");
            }),
            0U);
  EXPECT_EQ(ErrorOffset([&] {  // finite in metres, infinite in mm
              ParseStreamRecorderExtrinsics("1,0,0,1e308,0,1,0,0,0,0,1,0,0,0,0,1", "ext.txt");
            }),
            0U);
}

TEST(StreamRecorderRig2World, ParsesLinesByTimestampInMillimetres) {
  const std::string line1 = "133000000000000001,1,0,0,0.5,0,1,0,-0.25,0,0,1,2,0,0,0,1\r\n";
  const std::string line2 = "133000000000000002,0,-1,0,0,1,0,0,0,0,0,1,0,0,0,0,1\r\n";
  const auto poses = ParseStreamRecorderRig2World(line1 + "\r\n" + line2, "r2w.txt");
  ASSERT_EQ(poses.size(), 2U);
  EXPECT_THAT(poses.at(133000000000000001ULL),
              RigidNear(Rigid3d(Eigen::Quaterniond::Identity(), {500.0, -250.0, 2000.0}),
                        kNineDigitRotTolRad, kNineDigitTransTolMm));
  EXPECT_THAT(poses.at(133000000000000002ULL),
              RigidNear(RotZ(std::numbers::pi / 2, Eigen::Vector3d::Zero()), kNineDigitRotTolRad,
                        kNineDigitTransTolMm));

  const Rigid3d pose = RotZ(0.3, {1234.5678, -987.6543, 3210.0});
  const auto round_trip =
      ParseStreamRecorderRig2World(FormatStreamRecorderRig2WorldLine(42, pose), "r2w.txt");
  EXPECT_THAT(round_trip.at(42), RigidNear(pose, kNineDigitRotTolRad, kNineDigitTransTolMm));
}

TEST(StreamRecorderRig2World, MalformedLinesAreErrorsAtTheirOffset) {
  const std::string good = "1,1,0,0,0,0,1,0,0,0,0,1,0,0,0,0,1\n";
  const std::size_t second = good.size();
  std::string message;
  EXPECT_EQ(ErrorOffset(
                [&] {
                  ParseStreamRecorderRig2World(good + "2,1,0,0,0,0,1,0,0,0,0,1,0,0,0,0\n",
                                               "r2w.txt");
                },
                &message),
            second);
  EXPECT_NE(message.find("r2w.txt"), std::string::npos) << message;
  EXPECT_EQ(ErrorOffset([&] { ParseStreamRecorderRig2World(good + good, "r2w.txt"); }, &message),
            second);
  EXPECT_NE(message.find("duplicate"), std::string::npos) << message;
  EXPECT_EQ(
      ErrorOffset([&] { ParseStreamRecorderRig2World(good + "-2" + good.substr(1), "r2w.txt"); }),
      second);
  EXPECT_EQ(ErrorOffset([&] {
              ParseStreamRecorderRig2World(good + "99999999999999999999" + good.substr(1),
                                           "r2w.txt");
            }),
            second);
  EXPECT_TRUE(ParseStreamRecorderRig2World("\n\r\n", "r2w.txt").empty());
}

}  // namespace
}  // namespace tofnav
