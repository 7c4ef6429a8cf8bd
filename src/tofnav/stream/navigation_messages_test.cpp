// SPDX-License-Identifier: BSD-3-Clause
// Navigation messages: names, RAS frames, and no stale transform re-sent as current.
#include "tofnav/stream/navigation_messages.hpp"

#include <gtest/gtest.h>

#include <map>
#include <numbers>

#include "matchers.hpp"
#include "tofnav/stream/igtl_receiver.hpp"
#include "tofnav/stream/live_link.hpp"

namespace tofnav {
namespace {

constexpr double kFloatMm = 1e-3, kFloatRad = 1e-6;  // float32 on the wire

std::map<std::string, IgtlFrame> Decode(const std::vector<NamedMessage>& messages) {
  std::map<std::string, IgtlFrame> out;
  IgtlReceiver receiver("<test>");
  for (const NamedMessage& m : messages) {
    receiver.Feed(m.bytes, [&](const IgtlFrame& f) { out[f.header.device_name] = f; });
  }
  EXPECT_EQ(out.size(), messages.size());
  return out;
}

NavigationState Tracking() {
  NavigationState s;
  s.timestamp_s = 12.5;
  s.status = NavigationStatus::kTracking;
  s.reference_status = ToolStatus::kOk;
  s.ahat_from_tool =
      Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(2.0, Eigen::Vector3d::UnitX())), {5, -20, 430});
  s.world_from_rig = Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitY())),
                             {100, 1600, -40});
  s.world_from_image =
      Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(0.9, Eigen::Vector3d(1, 1, 0).normalized())),
              {-30, 1500, -200});
  return s;
}

TEST(NavigationMessages, RasToWorldMapsSlicerRasOntoTheChain) {
  const NavigationState s = Tracking();
  const auto frames = Decode(EncodeNavigationFrame(s, {}));
  ASSERT_TRUE(frames.count("RasToWorld"));
  ASSERT_TRUE(frames.count("ReferenceToAhat"));
  ASSERT_TRUE(frames.count("RigToWorld"));
  EXPECT_FALSE(frames.count("ToolToReference"));  // no instrument
  const Rigid3d ras_to_world = DecodeIgtlTransformContent(frames.at("RasToWorld").content);
  // A CT point in LPS, as Slicer holds it (RAS), lands where Eq. (8) puts it.
  const Eigen::Vector3d p_image(12.0, -34.0, 56.0);
  const Eigen::Vector3d p_ras(-12.0, 34.0, 56.0);
  EXPECT_NEAR((ras_to_world * p_ras - *s.world_from_image * p_image).norm(), 0.0, kFloatMm);
  EXPECT_THAT(DecodeIgtlTransformContent(frames.at("ReferenceToAhat").content),
              RigidNear(*s.ahat_from_tool, kFloatRad, kFloatMm));
  EXPECT_EQ(frames.at("RasToWorld").header.timestamp, IgtlTimestamp(12.5));
  EXPECT_EQ(DecodeIgtlStringContent(frames.at("NavigationStatus").content).rfind("TRACKING", 0),
            0u);
}

TEST(NavigationMessages, ASettlingReferenceSaysSoWithItsSd) {
  NavigationState s = Tracking();
  s.detected_markers = 4;
  s.reference_rotation_sd_rad = 0.5236 * std::numbers::pi / 180.0;
  s.reference_settling = true;
  const auto frames = Decode(EncodeNavigationFrame(s, {}));
  EXPECT_TRUE(frames.count("RasToWorld"));  // placed: the plan is shown, flagged
  EXPECT_EQ(DecodeIgtlStringContent(frames.at("NavigationStatus").content),
            "TRACKING t=12.500s ref=ok age=0ms SETTLING sd=0.52deg markers=4");
  s.reference_settling = false;
  EXPECT_EQ(NavigationStatusLine(s, {}), "TRACKING t=12.500s ref=ok age=0ms markers=4");
}

TEST(NavigationMessages, StaleReferenceSendsNoTransformAndSaysSo) {
  NavigationState s = Tracking();
  s.status = NavigationStatus::kReferenceLost;
  s.reference_status = ToolStatus::kOutOfView;
  s.reference_age_s = 0.25;
  s.ahat_from_tool.reset();
  s.world_from_image.reset();  // what the Navigator gives after 100 ms unseen
  const auto frames = Decode(EncodeNavigationFrame(s, {}));
  EXPECT_FALSE(frames.count("RasToWorld"));
  EXPECT_FALSE(frames.count("ReferenceToAhat"));
  const std::string line = DecodeIgtlStringContent(frames.at("NavigationStatus").content);
  EXPECT_EQ(line.rfind("REFERENCE_LOST", 0), 0u) << line;
  EXPECT_NE(line.find("age=250ms"), std::string::npos) << line;
}

TEST(NavigationMessages, GreetingsCarryRegistrationPlanAndSkin) {
  NavigationCase c;
  c.tool_from_image =
      Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(1.0, Eigen::Vector3d::UnitZ())), {3, 4, 5});
  c.plan = {{"right-1", {30, -80, 40}, {20, -30, 10}}};
  TriangleMesh skin;
  skin.vertices = {{1, 2, 3}, {4, 5, 6}, {7, 8, 10}};
  skin.triangles = {{0, 1, 2}};
  const auto frames = Decode(EncodeNavigationGreetings(c, Rigid3d(), skin, std::nullopt));
  const Rigid3d reference_to_ras = DecodeIgtlTransformContent(frames.at("ReferenceToRas").content);
  const Eigen::Vector3d p_image(10, 20, 30);
  const Eigen::Vector3d p_ras = RasFromImage() * p_image;
  EXPECT_NEAR((reference_to_ras * (c.tool_from_image * p_image) - p_ras).norm(), 0.0, kFloatMm);
  EXPECT_EQ(frames.at("Plan").content.size(), 2u * 136u);  // entry and target
  EXPECT_EQ(frames.at("SkinRas").content.size(), 92u);     // 3 points, 1 triangle
  EXPECT_TRUE(frames.count("AhatToRig"));
  EXPECT_FALSE(frames.count("HeadSurface"));
}

TEST(NavigationMessages, NoStreamSendsItsAgeAndNoTransform) {
  // 1.5 s after a tracked frame at 12.5 s: the status string only, RasToWorld stopped exactly
  // as for a lost reference (docs/navigation.md).
  const auto frames = Decode(EncodeNavigationFrame(NoStreamState(Tracking(), 1.5), {}));
  EXPECT_EQ(frames.size(), 1u);
  EXPECT_EQ(DecodeIgtlStringContent(frames.at("NavigationStatus").content),
            "NO_STREAM t=14.000s down=1.5s ref=out_of_view age=1500ms markers=0");
}

}  // namespace
}  // namespace tofnav
