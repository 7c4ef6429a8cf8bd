// SPDX-License-Identifier: BSD-3-Clause
// OpenIGTLink codec and receiver: reference bytes, libopenigtlink 1.11 Pack() oracle, v2, CRC.
#include "tofnav/stream/igtl_codec.hpp"

#include <gtest/gtest.h>
#include <igtlPointMessage.h>
#include <igtlPolyDataMessage.h>
#include <igtlStringMessage.h>
#include <igtlTransformMessage.h>

#include <string>
#include <vector>

#include "tofnav/core/require.hpp"
#include "tofnav/io/io_error.hpp"
#include "tofnav/stream/igtl_receiver.hpp"

namespace tofnav {
namespace {

using Bytes = std::vector<std::uint8_t>;

Bytes PackOf(igtl::MessageBase* m) {
  m->Pack();
  const auto* p = static_cast<const std::uint8_t*>(m->GetPackPointer());
  return {p, p + m->GetPackSize()};
}

std::span<const std::uint8_t> AsBytes(const std::string& s) {
  return {reinterpret_cast<const std::uint8_t*>(s.data()), s.size()};
}

TEST(IgtlCodec, Crc64CheckValue) {
  EXPECT_EQ(IgtlCrc64(AsBytes("123456789")), 0x6C40DF5F0B497347ULL);  // docs/openigtlink.md 2.1
  EXPECT_EQ(IgtlTimestamp(1700000000.5), 0x6553F10080000000ULL);
}

// docs/openigtlink.md 2.2: the 106 bytes 1.11's TransformMessage::Pack() writes.
TEST(IgtlCodec, TransformIsByteExactToTheReferenceDump) {
  const Bytes expected = {0x00, 0x01, 0x54, 0x52, 0x41, 0x4e, 0x53, 0x46, 0x4f, 0x52, 0x4d, 0x00,
                          0x00, 0x00, 0x54, 0x6f, 0x6f, 0x6c, 0x54, 0x6f, 0x52, 0x65, 0x66, 0x65,
                          0x72, 0x65, 0x6e, 0x63, 0x65, 0x00, 0x00, 0x00, 0x00, 0x00, 0x65, 0x53,
                          0xf1, 0x00, 0x80, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,
                          0x00, 0x30, 0xf4, 0x3c, 0xd9, 0x1f, 0x2d, 0x85, 0x2f, 0xc0, 0x3f, 0x80,
                          0x00, 0x00, 0xbe, 0x80, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x3f, 0x00,
                          0x00, 0x00, 0x3f, 0x80, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,
                          0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x3f, 0x80, 0x00, 0x00, 0x41, 0x20,
                          0x00, 0x00, 0x41, 0xa0, 0x00, 0x00, 0x41, 0xf0, 0x00, 0x00};
  Eigen::Matrix<double, 3, 4> m;
  m << 1.0, 0.5, 0.0, 10.0, -0.25, 1.0, 0.0, 20.0, 0.0, 0.0, 1.0, 30.0;
  EXPECT_EQ(EncodeIgtlMessage("TRANSFORM", "ToolToReference", 0x6553F10080000000ULL,
                              IgtlTransformContent(m)),
            expected);
}

TEST(IgtlCodec, EveryTypeMatchesLibOpenIgtlinkPack) {
  const std::uint64_t ts = IgtlTimestamp(12345.25);
  const auto sec = static_cast<unsigned>(ts >> 32), frac = static_cast<unsigned>(ts & 0xFFFFFFFF);
  // TRANSFORM of a rigid pose; a 20-character device name (not NUL-terminated on the wire).
  const Rigid3d pose(
      Eigen::Quaterniond(Eigen::AngleAxisd(0.8, Eigen::Vector3d(1, 2, 3).normalized())),
      {-12.5, 40.25, 310.0});
  igtl::TransformMessage::Pointer t = igtl::TransformMessage::New();
  t->SetDeviceName("ABCDEFGHIJKLMNOPQRST");
  igtl::Matrix4x4 m;
  const Eigen::Matrix4d pm = pose.ToMatrix();
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) m[r][c] = static_cast<float>(pm(r, c));
  }
  t->SetMatrix(m);
  t->SetTimeStamp(sec, frac);
  EXPECT_EQ(EncodeIgtlMessage("TRANSFORM", "ABCDEFGHIJKLMNOPQRST", ts, IgtlTransformContent(pose)),
            PackOf(t));
  // POINT: two elements.
  igtl::PointMessage::Pointer p = igtl::PointMessage::New();
  p->SetDeviceName("Plan");
  p->SetTimeStamp(sec, frac);
  std::vector<IgtlPoint> points = {
      {"right-1 entry", "Entry", {0, 255, 0, 255}, {1.5, -2, 3}, 4.0, "Ras"},
      {"right-1 target", "Target", {255, 0, 0, 255}, {-10, 20, 30}, 3.0, ""}};
  for (const IgtlPoint& q : points) {
    igtl::PointElement::Pointer e = igtl::PointElement::New();
    e->SetName(q.name.c_str());
    e->SetGroupName(q.group.c_str());
    e->SetRGBA(q.rgba[0], q.rgba[1], q.rgba[2], q.rgba[3]);
    e->SetPosition(static_cast<float>(q.position_mm.x()), static_cast<float>(q.position_mm.y()),
                   static_cast<float>(q.position_mm.z()));
    e->SetRadius(static_cast<float>(q.diameter_mm));  // 1.11 packs it into the DIAMETER field
    e->SetOwner(q.owner.c_str());
    p->AddPointElement(e);
  }
  const Bytes point_bytes = EncodeIgtlMessage("POINT", "Plan", ts, IgtlPointContent(points));
  EXPECT_EQ(point_bytes, PackOf(p));
  EXPECT_EQ(point_bytes.size(), kIgtlHeaderBytes + 2 * 136);
  // STRING.
  igtl::StringMessage::Pointer s = igtl::StringMessage::New();
  s->SetDeviceName("NavigationStatus");
  s->SetTimeStamp(sec, frac);
  s->SetString("abc");
  const Bytes string_bytes =
      EncodeIgtlMessage("STRING", "NavigationStatus", ts, IgtlStringContent("abc"));
  EXPECT_EQ(string_bytes, PackOf(s));
  EXPECT_EQ(string_bytes.size(), kIgtlHeaderBytes + 7);
  // POLYDATA: 3 points, 1 triangle.
  TriangleMesh mesh;
  mesh.vertices = {{0, 0, 0}, {10, 0, 0}, {0, 20, 5}};
  mesh.triangles = {{0, 1, 2}};
  igtl::PolyDataMessage::Pointer d = igtl::PolyDataMessage::New();
  d->SetDeviceName("Skin");
  d->SetTimeStamp(sec, frac);
  igtl::PolyDataPointArray::Pointer pts = igtl::PolyDataPointArray::New();
  for (const auto& v : mesh.vertices) {
    pts->AddPoint(static_cast<float>(v.x()), static_cast<float>(v.y()), static_cast<float>(v.z()));
  }
  igtl::PolyDataCellArray::Pointer polys = igtl::PolyDataCellArray::New();
  igtlUint32 cell[3] = {0, 1, 2};
  polys->AddCell(3, cell);
  d->SetPoints(pts);
  d->SetPolygons(polys);
  const Bytes poly_bytes = EncodeIgtlMessage("POLYDATA", "Skin", ts, IgtlPolyDataContent(mesh));
  EXPECT_EQ(poly_bytes, PackOf(d));
  EXPECT_EQ(poly_bytes.size(), kIgtlHeaderBytes + 92);
}

TEST(IgtlCodec, TransformRoundTrip) {
  const Rigid3d pose(
      Eigen::Quaterniond(Eigen::AngleAxisd(2.0, Eigen::Vector3d(0, 1, 1).normalized())),
      {1.0, 2.0, 3.0});
  const auto bytes = IgtlTransformContent(pose);
  const Rigid3d back = DecodeIgtlTransformContent(bytes);
  EXPECT_LT(TranslationDistanceMm(back, pose), 1e-6);  // float32 of small values
  EXPECT_LT(RotationDistanceRad(back, pose), 1e-6);
  EXPECT_THROW(EncodeIgtlMessage("TRANSFORM", "ABCDEFGHIJKLMNOPQRSTU", 0, bytes),
               PreconditionError);
}

TEST(IgtlReceiver, AcceptsV2SkipsBadCrcAndStaysInSync) {
  const std::vector<std::pair<std::string, std::string>> meta = {{"MRMLNodeName", "Slicer"},
                                                                 {"TransformStatus", "OK"}};
  const auto status_content = Bytes(33, 0);  // STATUS "ok"-sized body
  Bytes stream = EncodeIgtlMessageV2("STATUS", "", 0, status_content, {}, 1);
  Bytes bad = EncodeIgtlMessage("STRING", "Broken", 0, IgtlStringContent("corrupted"));
  bad.back() ^= 0x01;  // body changed after the CRC was computed
  stream.insert(stream.end(), bad.begin(), bad.end());
  const auto transform = IgtlTransformContent(Rigid3d({1, 0, 0, 0}, {5, 6, 7}));
  const Bytes v2 = EncodeIgtlMessageV2("TRANSFORM", "SlicerOut", 7, transform, meta, 2);
  EXPECT_EQ(v2.size(), kIgtlHeaderBytes + 12 + 48 + (2 + 16) + (12 + 6 + 15 + 2));
  stream.insert(stream.end(), v2.begin(), v2.end());
  const Bytes v1 = EncodeIgtlMessage("STRING", "After", 0, IgtlStringContent("still in sync"));
  stream.insert(stream.end(), v1.begin(), v1.end());

  IgtlReceiver receiver("<test>");
  std::vector<IgtlFrame> frames;
  // Byte by byte at first, then the rest in one chunk: framing must not depend on the chunks.
  for (std::size_t i = 0; i < 70; ++i) {
    receiver.Feed(std::span(stream).subspan(i, 1),
                  [&](const IgtlFrame& f) { frames.push_back(f); });
  }
  receiver.Feed(std::span(stream).subspan(70), [&](const IgtlFrame& f) { frames.push_back(f); });
  ASSERT_EQ(frames.size(), 3u);
  EXPECT_EQ(frames[0].header.type, "STATUS");
  EXPECT_EQ(frames[0].content.size(), 33u);
  EXPECT_EQ(frames[1].header.device_name, "SlicerOut");
  EXPECT_EQ(frames[1].metadata, meta);
  EXPECT_EQ(DecodeIgtlTransformContent(frames[1].content).translation, Eigen::Vector3d(5, 6, 7));
  EXPECT_EQ(DecodeIgtlStringContent(frames[2].content), "still in sync");
  EXPECT_EQ(receiver.counters().crc_errors, 1u);
  EXPECT_EQ(receiver.counters().v2_frames, 2u);
}

TEST(IgtlReceiver, FramingErrorsThrow) {
  Bytes frame = EncodeIgtlMessage("STRING", "x", 0, IgtlStringContent("y"));
  frame[1] = 3;  // version 3
  IgtlReceiver receiver("<test>");
  EXPECT_THROW(receiver.Feed(frame, nullptr), IoError);
  Bytes huge = EncodeIgtlMessage("IMAGE", "x", 0, {});
  huge[42] = 0x7F;  // BODY_SIZE far above the limit
  IgtlReceiver second("<test>");
  EXPECT_THROW(second.Feed(huge, nullptr), IoError);
  // A v2 body whose sizes do not add up is skipped (counted), not fatal.
  Bytes v2 = EncodeIgtlMessageV2("STATUS", "", 0, Bytes(4, 0), {}, 0);
  v2[kIgtlHeaderBytes + 1] = 200;  // extended header size 200 > body
  const std::uint64_t crc = IgtlCrc64(std::span(v2).subspan(kIgtlHeaderBytes));
  for (int i = 0; i < 8; ++i) v2[50 + i] = static_cast<std::uint8_t>(crc >> (56 - 8 * i));
  IgtlReceiver third("<test>");
  int delivered = 0;
  third.Feed(v2, [&](const IgtlFrame&) { ++delivered; });
  EXPECT_EQ(delivered, 0);
  EXPECT_EQ(third.counters().malformed_v2, 1u);
}

}  // namespace
}  // namespace tofnav
