// SPDX-License-Identifier: BSD-3-Clause
// Remote Unity scene: byte layout, the handedness conversion, primitives' placement, and the
// client against the fake server.
#include <gtest/gtest.h>

#include <random>

#include "tofnav/io/io_error.hpp"
#include "tofnav/stream/remote_scene_client.hpp"
#include "tofnav/stream_testing/fake_remote_scene_server.hpp"

namespace tofnav {
namespace {

constexpr double kExact = 1e-12;
constexpr double kFloatMm = 1e-3;  // float32 metres within 2 m of the origin: < 1 um

TEST(RemoteSceneProtocol, CommandsAreIdSizePayloadLittleEndian) {
  RemoteSceneCommands c;
  c.SetActive(0xAABBCCDDu, true);
  c.Say("on");
  c.RemoveAll();
  const std::vector<std::uint8_t> expected = {0x01, 0,    0,    0, 0x08, 0, 0, 0, 0xDD, 0xCC,
                                              0xBB, 0xAA, 0x01, 0, 0,    0,  // set active
                                              0x08, 0,    0,    0, 0x02, 0, 0, 0, 'o',  'n',  // say
                                              0x11, 0,    0,    0, 0x00, 0, 0, 0};  // remove all
  EXPECT_EQ(std::vector<std::uint8_t>(c.bytes().begin(), c.bytes().end()), expected);
  EXPECT_EQ(c.count(), 3u);
}

TEST(RemoteSceneProtocol, PayloadSizesMatchThePlugin) {
  RemoteSceneCommands c;
  c.CreatePrimitive(UnityPrimitive::kCylinder);
  c.SetWorldTransform(7, UnityTransform{});
  c.SetColour(7, {0.1f, 0.2f, 0.3f, 0.4f});
  c.SetText(7, 0.5f, {}, "abc");
  c.CreateText();
  c.SetTargetMode(1);
  std::vector<std::uint8_t> stream(c.bytes().begin(), c.bytes().end());
  stream.push_back(0x10);  // an incomplete next header stays behind
  const std::vector<RemoteSceneCommand> commands = TakeRemoteSceneCommands(stream, "<test>");
  ASSERT_EQ(commands.size(), 6u);
  const std::size_t sizes[] = {4, 44, 20, 27, 0, 4};  // u32 key + 10 floats; key + rgba; ...
  const std::uint32_t ids[] = {0, 2, 4, 7, 6, 20};
  for (std::size_t i = 0; i < 6; ++i) {
    EXPECT_EQ(commands[i].id, ids[i]);
    EXPECT_EQ(commands[i].payload.size(), sizes[i]);
  }
  EXPECT_EQ(stream.size(), 1u);
}

TEST(RemoteSceneProtocol, OversizedPayloadIsAnError) {
  std::vector<std::uint8_t> stream = {8, 0, 0, 0, 0xFF, 0xFF, 0xFF, 0x7F};
  EXPECT_THROW(TakeRemoteSceneCommands(stream, "<test>"), IoError);
}

TEST(RemoteSceneFrames, PointsNegateZAndScaleToMetres) {
  const Eigen::Vector3d p(120.0, -35.5, 800.0);
  EXPECT_LT((UnityFromWorldPoint(p) - Eigen::Vector3d(0.12, -0.0355, -0.8)).norm(), kExact);
  EXPECT_LT((WorldFromUnityPoint(UnityFromWorldPoint(p)) - p).norm(), kExact);
}

// M R M maps rotated points consistently: Unity(R p) = (M R M) Unity(p), for any rotation.
TEST(RemoteSceneFrames, RotationsAreConjugatedByTheMirror) {
  std::mt19937 rng(3);
  std::normal_distribution<double> n;
  for (int i = 0; i < 20; ++i) {
    const Eigen::Quaterniond r = Eigen::Quaterniond(n(rng), n(rng), n(rng), n(rng)).normalized();
    const Eigen::Vector3d p(n(rng) * 100, n(rng) * 100, n(rng) * 100);
    const Eigen::Quaterniond mirrored = MirrorZ(r);
    EXPECT_LT((UnityFromWorldPoint(r * p) - mirrored * UnityFromWorldPoint(p)).norm(), kExact);
    EXPECT_LT(MirrorZ(mirrored).angularDistance(r), 1e-9);  // its own inverse
  }
}

TEST(RemoteSceneFrames, CylinderRunsFromAToBAlongLocalY) {
  const Eigen::Vector3d a(10.0, 1500.0, -300.0), b(40.0, 1450.0, -380.0);
  const UnityTransform t = UnityCylinder(a, b, 2.0);
  const auto [bottom, top] = WorldCylinderEnds(t);
  EXPECT_LT((bottom - a).norm(), kFloatMm);
  EXPECT_LT((top - b).norm(), kFloatMm);
  EXPECT_NEAR(t.scale.x(), 0.002f, 1e-7f);  // diameter in metres
  EXPECT_NEAR(t.scale.z(), 0.002f, 1e-7f);
  EXPECT_NEAR(t.scale.y(), 0.5 * (b - a).norm() * 1e-3, 1e-7);  // half length: 2 units long
  EXPECT_LT((t.position_m.cast<double>() - UnityFromWorldPoint(0.5 * (a + b))).norm(), 1e-6);
  const UnityTransform s = UnitySphere(a, 5.0);
  EXPECT_NEAR(s.scale.x(), 0.005f, 1e-7f);
}

TEST(RemoteSceneFrames, TextPanelFacesTheViewerUpright) {
  const Eigen::Vector3d at(0.0, 1600.0, -400.0), viewer(200.0, 1700.0, 200.0);
  const UnityTransform t = UnityTextPanel(at, viewer, Eigen::Vector3d::UnitY());
  const Eigen::Matrix3d r = t.rotation.cast<double>().toRotationMatrix();
  EXPECT_NEAR(r.determinant(), 1.0, 1e-6);
  const Eigen::Vector3d look = (UnityFromWorldPoint(at) - UnityFromWorldPoint(viewer)).normalized();
  EXPECT_GT(r.col(2).dot(look), 1.0 - 1e-6);  // text read along its +z
  EXPECT_NEAR(r.col(0).y(), 0.0, 1e-6);       // horizontal lines
  EXPECT_GT(r.col(1).y(), 0.0);
}

TEST(RemoteSceneClient, KeysAndResultsComeBackPerCommand) {
  FakeRemoteSceneServer server;
  RemoteSceneClient client("127.0.0.1", server.port(), 2.0);
  RemoteSceneCommands create;
  create.CreatePrimitive(UnityPrimitive::kSphere);
  create.CreateText();
  const std::vector<std::uint32_t> keys = client.Push(create);
  ASSERT_EQ(keys.size(), 2u);
  EXPECT_NE(keys[0], 0u);
  EXPECT_NE(keys[0], keys[1]);
  RemoteSceneCommands c;
  c.BeginDisplayList();
  c.SetWorldTransform(keys[0], UnitySphere({1.0, 2.0, 3.0}, 4.0));
  c.SetActive(keys[0], true);
  c.SetText(keys[1], 0.2f, {1, 0, 0, 1}, "12.3 mm");
  c.SetColour(12345, {});  // unknown key: rejected
  c.EndDisplayList();
  EXPECT_EQ(client.Push(c), (std::vector<std::uint32_t>{1, 1, 1, 1, 0, 1}));
  const FakeRemoteScene scene = server.scene();
  ASSERT_EQ(scene.objects.size(), 2u);
  const FakeSceneObject& sphere = scene.objects.at(keys[0]);
  EXPECT_TRUE(sphere.active);
  EXPECT_LT((WorldFromUnityPoint(sphere.transform.position_m.cast<double>()) -
             Eigen::Vector3d(1.0, 2.0, 3.0))
                .norm(),
            kFloatMm);
  EXPECT_EQ(scene.objects.at(keys[1]).text, "12.3 mm");
  EXPECT_EQ(server.stats().rejected, 1u);
}

TEST(RemoteSceneClient, EndpointParsing) {
  EXPECT_EQ(ParseRemoteSceneEndpoint("192.168.1.7"),
            std::make_pair(std::string("192.168.1.7"), kRemoteScenePort));
  EXPECT_EQ(ParseRemoteSceneEndpoint("hl:4000"), std::make_pair(std::string("hl"), 4000));
  EXPECT_ANY_THROW(ParseRemoteSceneEndpoint(":4000"));
  EXPECT_ANY_THROW(ParseRemoteSceneEndpoint("hl:port"));
}

TEST(RemoteSceneClient, NoServerIsAnIoErrorWithinTheTimeout) {
  EXPECT_THROW(RemoteSceneClient("127.0.0.1", ClosedLoopbackPort(), 0.5), IoError);
}

// The stand-in's frame loop (issue 37): the plugin runs one command per Unity frame outside a
// display list and the whole list in one frame.
TEST(RemoteSceneStandIn, OneCommandPerFrameOutsideDisplayListsAWholeListInOne) {
  FakeRemoteSceneServer server(0, {.frame_rate_hz = 60.0});
  RemoteSceneClient client("127.0.0.1", server.port(), 5.0);
  RemoteSceneCommands loose;
  for (int i = 0; i < 6; ++i) loose.CreateText();
  const std::uint64_t before = server.stats().frames;
  ASSERT_EQ(client.Push(loose).size(), 6u);
  EXPECT_GE(server.stats().frames - before, 6u);  // one per frame
  RemoteSceneCommands list;
  list.BeginDisplayList();
  for (int i = 0; i < 6; ++i) list.CreateText();
  list.EndDisplayList();
  const std::uint64_t lists_before = server.scene().display_lists;
  const std::uint64_t frames_before_list = server.stats().frames;
  ASSERT_EQ(client.Push(list).size(), 8u);
  ASSERT_TRUE(server.WaitForDisplayLists(lists_before + 1, 5.0));
  const FakeRemoteScene scene = server.scene();
  EXPECT_EQ(scene.objects.size(), 12u);
  // Eight commands one per frame would take eight frames; the list runs in the first frame
  // after it arrived (two allow for a frame under way when it arrived).
  EXPECT_LE(scene.frame - frames_before_list, 2u);
}

TEST(RemoteSceneStandIn, ASecondClientGetsNoReplyWhileTheFirstIsConnected) {
  FakeRemoteSceneServer server;
  RemoteSceneClient first("127.0.0.1", server.port(), 2.0);
  RemoteSceneCommands c;
  c.CreateText();
  ASSERT_EQ(first.Push(c).size(), 1u);
  RemoteSceneClient second("127.0.0.1", server.port(), 0.3);  // the kernel accepts it
  EXPECT_THROW(second.Push(c), IoError);                      // the plugin does not answer
  EXPECT_EQ(first.Push(c).size(), 1u);                        // the first goes on
  EXPECT_EQ(server.stats().connections, 1u);
}

TEST(RemoteSceneStandIn, SayWithoutSpeechIsNeverAnswered) {
  FakeRemoteSceneServer server(0, {.say_answers = false});
  RemoteSceneClient client("127.0.0.1", server.port(), 0.3);
  RemoteSceneCommands c;
  c.Say("on target");
  EXPECT_THROW(client.Push(c), IoError);
  EXPECT_TRUE(server.scene().spoken.empty());
}

TEST(RemoteSceneStandIn, NothingIsDestroyedOnDisconnect) {
  FakeRemoteSceneServer server;
  {
    RemoteSceneClient client("127.0.0.1", server.port(), 2.0);
    RemoteSceneCommands c;
    c.CreateText();
    c.CreatePrimitive(UnityPrimitive::kSphere);
    ASSERT_EQ(client.Push(c).size(), 2u);
  }
  RemoteSceneClient next("127.0.0.1", server.port(), 2.0);  // accepted once the first is gone
  RemoteSceneCommands c;
  c.CreateText();
  ASSERT_EQ(next.Push(c).size(), 1u);
  EXPECT_EQ(server.scene().objects.size(), 3u);  // the first client's holograms stay
}

}  // namespace
}  // namespace tofnav
