// SPDX-License-Identifier: BSD-3-Clause
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>
#include <string_view>

#include "tofnav/io/binary.hpp"
#include "tofnav/io/io_error.hpp"
#include "tofnav/mesh/mesh_io.hpp"

namespace tofnav {
namespace {

using ::testing::HasSubstr;

std::vector<std::uint8_t> Bytes(std::string_view text) { return {text.begin(), text.end()}; }

// Lines 1-21 header, 22-25 vertices, 26-27 the skipped "edge" element, 28-29 faces.
constexpr std::string_view kGoldenAscii =
    "ply\n"
    "format ascii 1.0\n"
    "comment hand-written golden file\n"
    "obj_info tofnav test\n"
    "element vertex 4\n"
    "property float x\n"
    "property float y\n"
    "property float z\n"
    "property float nx\n"
    "property float ny\n"
    "property float nz\n"
    "property uchar red\n"
    "property uchar green\n"
    "property uchar blue\n"
    "property float quality\n"
    "element edge 2\n"
    "property int vertex1\n"
    "property list uchar int path\n"
    "element face 2\n"
    "property list uchar int vertex_indices\n"
    "end_header\n"
    "0 0 0 0 0 1 255 0 0 0.5\n"
    "10 0 0 0 0 1 0 255 0 1.5\n"
    "10 20 0 0 0 1 0 0 255 -2.25\n"
    "0 20 0 0 0 1 10 20 30 1e3\n"
    "0 2 0 1\n"
    "1 3 1 2 3\n"
    "4 0 1 2 3\n"
    "3 0 2 1\n";

IoError DecodeError(std::string_view text) {
  try {
    DecodePly(Bytes(text), "bad.ply");
  } catch (const IoError& e) {
    return e;
  }
  ADD_FAILURE() << "no IoError";
  return IoError("bad.ply", std::nullopt, "none");
}

std::string Replace(std::string_view text, std::string_view from, std::string_view to) {
  std::string out(text);
  const std::size_t at = out.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return out.replace(at, from.size(), to);
}

TEST(DecodePly, GoldenAsciiWithQuadAndSkippedListElement) {
  const TriangleMesh mesh = DecodePly(Bytes(kGoldenAscii), "golden.ply");
  ASSERT_EQ(mesh.vertices.size(), 4u);
  EXPECT_EQ(mesh.vertices[2], Eigen::Vector3d(10, 20, 0));
  ASSERT_EQ(mesh.vertex_normals.size(), 4u);
  EXPECT_EQ(mesh.vertex_normals[3], Eigen::Vector3d(0, 0, 1));
  ASSERT_EQ(mesh.vertex_colors.size(), 4u);
  EXPECT_EQ(mesh.vertex_colors[3], Rgb8(10, 20, 30));
  EXPECT_THAT(mesh.vertex_scalars, ::testing::ElementsAre(0.5f, 1.5f, -2.25f, 1000.0f));
  ASSERT_EQ(mesh.triangles.size(), 3u);  // the quad becomes a fan of two
  EXPECT_EQ(mesh.triangles[0], Eigen::Vector3i(0, 1, 2));
  EXPECT_EQ(mesh.triangles[1], Eigen::Vector3i(0, 2, 3));
  EXPECT_EQ(mesh.triangles[2], Eigen::Vector3i(0, 2, 1));
}

TEST(DecodePly, HandAssembledBinaryBigEndian) {
  ByteWriter out;
  out.Text(
      "ply\r\nformat binary_big_endian 1.0\r\n"
      "element vertex 4\nproperty double x\nproperty float y\nproperty int16 z\n"
      "property float32 red\nproperty float32 green\nproperty float32 blue\n"
      "property uint16 intensity\nproperty list uint8 float32 extra_list\n"
      "element extra 2\nproperty list int32 float64 data\nproperty char flag\n"
      "element face 1\nproperty uchar flags\nproperty list uint int16 vertex_index\n"
      "end_header\n");
  const double xs[] = {1.25, -2.5, 3.0, 1e-3};
  for (int v = 0; v < 4; ++v) {
    out.Be(xs[v]);
    out.Be(static_cast<float>(10 * v));
    out.Be(static_cast<std::int16_t>(-v));
    out.Be(1.0f);  // 0..1 float colours are scaled to 0..255
    out.Be(0.5f);
    out.Be(0.0f);
    out.Be(static_cast<std::uint16_t>(500 + v));
    out.Be(std::uint8_t{2});
    out.Be(7.0f);
    out.Be(8.0f);
  }
  for (int e = 0; e < 2; ++e) {
    out.Be(std::int32_t{1});
    out.Be(3.5);
    out.Be(std::int8_t{-1});
  }
  out.Be(std::uint8_t{9});
  out.Be(std::uint32_t{4});
  for (int i = 0; i < 4; ++i) out.Be(static_cast<std::int16_t>(i));

  const TriangleMesh mesh = DecodePly(out.bytes(), "be.ply");
  ASSERT_EQ(mesh.vertices.size(), 4u);
  for (int v = 0; v < 4; ++v) EXPECT_EQ(mesh.vertices[v], Eigen::Vector3d(xs[v], 10 * v, -v));
  EXPECT_TRUE(mesh.vertex_normals.empty());
  EXPECT_EQ(mesh.vertex_colors[1], Rgb8(255, 128, 0));  // 0.5 * 255 = 127.5 rounds up
  EXPECT_THAT(mesh.vertex_scalars, ::testing::ElementsAre(500.f, 501.f, 502.f, 503.f));
  ASSERT_EQ(mesh.triangles.size(), 2u);
  EXPECT_EQ(mesh.triangles[0], Eigen::Vector3i(0, 1, 2));
  EXPECT_EQ(mesh.triangles[1], Eigen::Vector3i(0, 2, 3));
}

TEST(DecodePly, ScalarPropertyPreference) {
  const std::string text =
      "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
      "property float z\nproperty float value\nproperty float quality\nend_header\n0 0 0 1 2\n";
  EXPECT_THAT(DecodePly(Bytes(text), "s.ply").vertex_scalars, ::testing::ElementsAre(2.f));
  EXPECT_THAT(DecodePly(Bytes(text), "s.ply", {.scalar_name = "value"}).vertex_scalars,
              ::testing::ElementsAre(1.f));
}

TEST(DecodePly, AsciiAndBinaryRoundTripIsExactForFloatData) {
  TriangleMesh mesh;
  mesh.vertices = {{0, 0, 0}, {12.5, -3.25, 1e-7f}, {0.1f, 1e6, -7}, {3, 4, 5}};
  mesh.vertex_normals = {{0, 0, 1}, {0.6f, 0.8f, 0}, {-1, 0, 0}, {0, -0.28f, 0.96f}};
  mesh.vertex_colors = {Rgb8(0, 0, 0), Rgb8(255, 1, 2), Rgb8(7, 8, 9), Rgb8(100, 200, 50)};
  mesh.vertex_scalars = {0.f, -1.5f, 3.3f, 1e-20f};
  mesh.triangles = {{0, 1, 2}, {0, 2, 3}, {3, 2, 1}};
  for (const bool binary : {true, false}) {
    const MeshWriteOptions options{.binary = binary, .scalar_name = "dist_mm"};
    const TriangleMesh back =
        DecodePly(EncodePly(mesh, options), "rt.ply", {.scalar_name = "dist_mm"});
    EXPECT_EQ(back.vertices, mesh.vertices) << "binary " << binary;
    EXPECT_EQ(back.vertex_normals, mesh.vertex_normals);
    EXPECT_EQ(back.vertex_colors, mesh.vertex_colors);
    EXPECT_EQ(back.vertex_scalars, mesh.vertex_scalars);
    EXPECT_EQ(back.triangles, mesh.triangles);
  }
}

TEST(DecodePly, GarbageAsciiNumberNamesItsLine) {
  const std::string text = Replace(kGoldenAscii, "-2.25", "-2.2x5");
  const IoError e = DecodeError(text);
  EXPECT_EQ(e.offset(), text.find("-2.2x5"));
  EXPECT_THAT(e.what(), HasSubstr("line 24"));
  EXPECT_THAT(e.what(), HasSubstr("property 'quality'"));
}

TEST(DecodePly, BadPropertyTypeNamesItsLine) {
  const IoError e = DecodeError(Replace(kGoldenAscii, "property float y", "property flaot y"));
  EXPECT_THAT(e.what(), HasSubstr("line 7"));
  EXPECT_THAT(e.what(), HasSubstr("'flaot'"));
}

TEST(DecodePly, FaceIndexOutOfRange) {
  const IoError e = DecodeError(Replace(kGoldenAscii, "3 0 2 1\n", "3 0 2 4\n"));
  EXPECT_THAT(e.what(), HasSubstr("line 29"));
  EXPECT_THAT(e.what(), HasSubstr("vertex index 4 out of range [0, 4)"));
}

TEST(DecodePly, UcharOutOfRangeAndMissingEndHeader) {
  EXPECT_THAT(DecodeError(Replace(kGoldenAscii, "255 0 0 0.5", "256 0 0 0.5")).what(),
              HasSubstr("out of range for element 'vertex' property 'red'"));
  EXPECT_THAT(DecodeError(Replace(kGoldenAscii, "end_header\n", "")).what(),
              HasSubstr("expected a PLY header keyword"));
}

TEST(DecodePly, VertexCountLargerThanTheFile) {
  for (const char* format : {"ascii", "binary_little_endian"}) {
    const std::string text = std::string("ply\nformat ") + format +
                             " 1.0\nelement vertex 2000000000\nproperty float x\n"
                             "property float y\nproperty float z\nend_header\n0 0 0\n";
    const IoError e = DecodeError(text);
    EXPECT_EQ(e.offset(), text.find("end_header\n") + 11) << format;
    EXPECT_THAT(e.what(), HasSubstr("declares 2000000000 instances"));
  }
}

TEST(DecodePly, TruncatedBinaryBody) {
  TriangleMesh mesh;
  mesh.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  mesh.triangles = {{0, 1, 2}};
  std::vector<std::uint8_t> bytes = EncodePly(mesh);
  bytes.resize(bytes.size() - 5);  // cut inside the face's indices
  try {
    DecodePly(bytes, "cut.ply");
    FAIL();
  } catch (const IoError& e) {
    EXPECT_EQ(e.offset(), bytes.size() - 3);  // 13-byte face: count + 3 ints, 8 bytes remain
    EXPECT_THAT(e.what(), HasSubstr("expected 4 bytes of element 'face'"));
  }
}

TEST(DecodePly, NegativeBinaryListCountAndShortFace) {
  const std::string header =
      "ply\nformat binary_little_endian 1.0\nelement vertex 0\nproperty float x\n"
      "property float y\nproperty float z\nelement face 1\nproperty list char int vertex_indices\n"
      "end_header\n";
  std::string negative = header + "\xff";
  negative += std::string(8, '\0');
  EXPECT_THAT(DecodeError(negative).what(), HasSubstr("negative list count"));
  std::string two = header + "\x02";
  two += std::string(8, '\0');
  EXPECT_THAT(DecodeError(two).what(), HasSubstr("a face with 2 corners"));
}

}  // namespace
}  // namespace tofnav
