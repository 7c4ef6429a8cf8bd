// SPDX-License-Identifier: BSD-3-Clause
// tofnav verify's outputs besides the terminal: Slicer's STRING and POINT, the headset panel.
#include "tofnav/stream/verify_messages.hpp"

#include <gtest/gtest.h>

#include <cstring>
#include <map>

#include "tofnav/stream/headset_scene.hpp"
#include "tofnav/stream/igtl_codec.hpp"
#include "tofnav/stream/igtl_receiver.hpp"

namespace tofnav {
namespace {

constexpr double kFloatMm = 1e-3;  // float32 on the wire
const Eigen::Vector3d kTip(0.0, 0.0, 150.0);

const Rigid3d kToolFromImage(Eigen::Quaterniond(Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitZ())),
                             Eigen::Vector3d(10.0, -30.0, 200.0));

std::vector<Landmark> TwoLandmarks() {
  return {{"nasion", {0.0, -95.0, 10.0}}, {"forehead", {0.0, -80.0, 60.0}}};
}

// 1.2 s of the pointer's tip resting exactly at `tip_in_image`.
void Rest(LandmarkCheck& check, const Eigen::Vector3d& tip_in_image, double& t_s) {
  for (int k = 0; k < 54; ++k, t_s += 1.0 / 45.0) {
    NavigationState s;
    s.timestamp_s = t_s;
    s.tool_from_instrument =
        Rigid3d(Eigen::Quaterniond::Identity(), kToolFromImage * tip_in_image - kTip);
    check.Add(s);
  }
}

std::map<std::string, IgtlFrame> Decode(const std::vector<NamedMessage>& messages) {
  std::map<std::string, IgtlFrame> out;
  IgtlReceiver receiver("<test>");
  for (const NamedMessage& m : messages) {
    receiver.Feed(m.bytes, [&](const IgtlFrame& f) { out[f.header.device_name] = f; });
  }
  return out;
}

TEST(VerifyMessages, SlicerGetsTheLineAndEachTouchInRas) {
  LandmarkCheck check(TwoLandmarks(), kToolFromImage, kTip);
  auto frames = Decode(EncodeLandmarkCheck(check, 10.0));
  EXPECT_EQ(DecodeIgtlStringContent(frames.at("VerifyStatus").content),
            "verify: touch nasion (1 of 2)");
  EXPECT_FALSE(frames.count("VerifyTouches"));  // nothing touched yet

  double t_s = 10.0;
  const Eigen::Vector3d touched = TwoLandmarks()[0].in_image + Eigen::Vector3d(1.0, 0.0, 0.0);
  Rest(check, touched, t_s);
  frames = Decode(EncodeLandmarkCheck(check, t_s));
  EXPECT_EQ(DecodeIgtlStringContent(frames.at("VerifyStatus").content),
            "verify: touch forehead (2 of 2); nasion 1.00 mm ok");
  // One POINT element: name char[64], group char[32], RGBA, XYZ float32 (RAS mm), ...
  const std::vector<std::uint8_t>& point = frames.at("VerifyTouches").content;
  ASSERT_EQ(point.size(), 136u);
  EXPECT_STREQ(reinterpret_cast<const char*>(point.data()), "nasion 1.00 mm");
  EXPECT_STREQ(reinterpret_cast<const char*>(point.data() + 64), "Touch");
  EXPECT_EQ(point[96], 0);  // green: passed
  EXPECT_EQ(point[97], 200);
  float xyz[3];
  for (int k = 0; k < 3; ++k) {  // big-endian float32
    const std::uint32_t bits = (std::uint32_t{point[100 + 4 * k]} << 24) |
                               (std::uint32_t{point[101 + 4 * k]} << 16) |
                               (std::uint32_t{point[102 + 4 * k]} << 8) | point[103 + 4 * k];
    std::memcpy(&xyz[k], &bits, 4);
  }
  const Eigen::Vector3d ras = RasFromImage() * touched;
  EXPECT_NEAR((Eigen::Vector3d(xyz[0], xyz[1], xyz[2]) - ras).norm(), 0.0, kFloatMm);

  const auto greeting = Decode({EncodeLandmarksGreeting(TwoLandmarks())});
  EXPECT_EQ(greeting.at("Landmarks").content.size(), 2u * 136u);
}

// Without a plan the panel stands over the first landmark and leads with the check's line.
TEST(VerifyMessages, ThePanelLeadsWithTheCheckAndStandsOverTheLandmark) {
  NavigationState s;
  s.status = NavigationStatus::kTracking;
  s.timestamp_s = 3.0;
  s.world_from_rig = Rigid3d(Eigen::Quaterniond::Identity(), {0.0, 1600.0, 300.0});
  s.world_from_image = Rigid3d(Eigen::Quaterniond::Identity(), {100.0, 1400.0, -350.0});
  const PanelNote note{"verify: touch nasion (1 of 2)", TwoLandmarks()[0].in_image};
  const HeadsetSceneOptions options;
  const HeadsetScene scene = ComposeHeadsetScene(s, {}, options, note);
  ASSERT_TRUE(scene.shown);
  const Hologram& panel = scene.holograms[TextPanelSlot(0)];
  EXPECT_TRUE(panel.visible);
  EXPECT_EQ(panel.text, "verify: touch nasion (1 of 2)\nlive 3.00 s");
  const Eigen::Vector3d expected = *s.world_from_image * note.anchor_in_image.value() +
                                   options.text_offset_mm * options.up_in_world;
  EXPECT_LT((panel.a_in_world - expected).norm(), 1e-9);
}

}  // namespace
}  // namespace tofnav
