// SPDX-License-Identifier: BSD-3-Clause
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>
#include <string_view>

#include "tofnav/io/io_error.hpp"
#include "tofnav/mesh/mesh_io.hpp"

namespace tofnav {
namespace {

using ::testing::HasSubstr;

std::vector<std::uint8_t> Bytes(std::string_view text) { return {text.begin(), text.end()}; }

// Line 12 holds the quad; its last corner uses negative (relative) indices.
constexpr std::string_view kHandWritten =
    "# hand-written OBJ\n"
    "mtllib none.mtl\n"
    "o square\n"
    "v 0 0 0\n"
    "v 10 0 0\n"
    "v 10 10 0\n"
    "v 0 10 0   # trailing comment\n"
    "vt 0 0\n"
    "vt 1 1\n"
    "vn 0 0 1\n"
    "s off\n"
    "f 1/1/1 2/2/1 3/1/1 -1/-2/-1\n"
    "f 1//1 3//1 2//1\n";

TEST(DecodeObj, HandWrittenWithTexturesNormalsAndNegativeIndices) {
  const TriangleMesh mesh = DecodeObj(Bytes(kHandWritten), "h.obj");
  ASSERT_EQ(mesh.vertices.size(), 4u);
  EXPECT_EQ(mesh.vertices[3], Eigen::Vector3d(0, 10, 0));
  ASSERT_EQ(mesh.triangles.size(), 3u);  // the quad becomes a fan of two
  EXPECT_EQ(mesh.triangles[0], Eigen::Vector3i(0, 1, 2));
  EXPECT_EQ(mesh.triangles[1], Eigen::Vector3i(0, 2, 3));
  EXPECT_EQ(mesh.triangles[2], Eigen::Vector3i(0, 2, 1));
  ASSERT_EQ(mesh.vertex_normals.size(), 4u);
  EXPECT_EQ(mesh.vertex_normals[3], Eigen::Vector3d(0, 0, 1));
  EXPECT_TRUE(mesh.vertex_colors.empty());
}

TEST(DecodeObj, RoundTripIsExactForDoubles) {
  TriangleMesh mesh;
  mesh.vertices = {{0.1, -1.0 / 3.0, 1e-300}, {12345.678901234567, 2, 3}, {-0.0, 5e10, 7}};
  mesh.vertex_normals = {Eigen::Vector3d(1, 2, 3).normalized(), {0, 0, 1}, {0, -1, 0}};
  mesh.vertex_colors = {Rgb8(0, 1, 2), Rgb8(128, 254, 255), Rgb8(17, 34, 51)};
  mesh.triangles = {{0, 1, 2}, {2, 1, 0}};
  const TriangleMesh back = DecodeObj(Bytes(EncodeObj(mesh)), "rt.obj");
  EXPECT_EQ(back.vertices, mesh.vertices);
  EXPECT_EQ(back.vertex_normals, mesh.vertex_normals);
  EXPECT_EQ(back.vertex_colors, mesh.vertex_colors);
  EXPECT_EQ(back.triangles, mesh.triangles);
}

TEST(DecodeObj, DifferingCornerNormalsAreAveraged) {
  const TriangleMesh mesh = DecodeObj(
      Bytes("v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 1 0 0\nvn 0 1 0\nf 1//1 2//1 3//1\nf 1//2 3//2 2//2\n"),
      "n.obj");
  constexpr double kTol = 1e-15;  // one normalisation in double precision
  ASSERT_EQ(mesh.vertex_normals.size(), 3u);
  EXPECT_TRUE(mesh.vertex_normals[0].isApprox(Eigen::Vector3d(1, 1, 0).normalized(), kTol));
}

IoError DecodeError(std::string_view text) {
  try {
    DecodeObj(Bytes(text), "bad.obj");
  } catch (const IoError& e) {
    return e;
  }
  ADD_FAILURE() << "no IoError";
  return IoError("bad.obj", std::nullopt, "none");
}

TEST(DecodeObj, MalformedInputNamesTheLine) {
  const std::string bad_index = std::string(kHandWritten) + "f 1 2 5\n";
  const IoError e = DecodeError(bad_index);
  EXPECT_EQ(e.offset(), bad_index.size() - 2);
  EXPECT_THAT(e.what(), HasSubstr("line 14: vertex index 5 out of range: 4 defined so far"));
  EXPECT_THAT(DecodeError("v 0 0 0\nf 0 1 1\n").what(), HasSubstr("line 2: vertex index 0"));
  EXPECT_THAT(DecodeError("v 0 0 0\nf 1 1\n").what(), HasSubstr("a face with 2 corners"));
  EXPECT_THAT(DecodeError("v 0 0\n").what(), HasSubstr("line 1: expected 'v x y z [w]'"));
  EXPECT_THAT(DecodeError("\n\nv 0 0 zero\n").what(),
              HasSubstr("line 3: expected a number on a 'v' line, found 'zero'"));
  EXPECT_THAT(DecodeError("v 0 0 0\nvn 0 0 1\nf 1//2 1 1\n").what(),
              HasSubstr("normal index 2 out of range"));
}

}  // namespace
}  // namespace tofnav
