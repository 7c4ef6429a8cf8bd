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

/// A closed tetrahedron whose coordinates are exact floats.
TriangleMesh Tetrahedron() {
  TriangleMesh mesh;
  mesh.vertices = {{0, 0, 0}, {10.5, 0, 0}, {0, 20.25, 0}, {0.1f, 0.2f, -3.125}};
  mesh.triangles = {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {2, 0, 3}};
  return mesh;
}

TEST(DecodeStl, BinaryRoundTripMergesCornersBackIntoSharedVertices) {
  const TriangleMesh mesh = Tetrahedron();
  const std::vector<std::uint8_t> bytes = EncodeStl(mesh);
  ASSERT_EQ(bytes.size(), 84u + 50u * 4u);
  const TriangleMesh back = DecodeStl(bytes, "t.stl");
  ASSERT_EQ(back.triangles.size(), mesh.triangles.size());
  EXPECT_EQ(back.vertices.size(), 4u);  // 12 facet corners, 4 distinct positions
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    for (int c = 0; c < 3; ++c) {
      EXPECT_EQ(back.vertices[back.triangles[t][c]], mesh.vertices[mesh.triangles[t][c]]);
    }
  }
}

TEST(DecodeStl, BinaryWhoseHeaderStartsWithSolid) {
  ByteWriter out;
  std::string header = "solid this is binary";
  header.resize(80, '\0');
  out.Text(header);
  out.Le(std::uint32_t{1});
  for (float v : {0.f, 0.f, 1.f, 1.f, 2.f, 3.f, 4.f, 5.f, 6.f, 7.f, 8.f, 9.f}) out.Le(v);
  out.Le(std::uint16_t{0});
  const TriangleMesh mesh = DecodeStl(out.bytes(), "solid.stl");
  ASSERT_EQ(mesh.vertices.size(), 3u);
  EXPECT_EQ(mesh.vertices[2], Eigen::Vector3d(7, 8, 9));
  EXPECT_EQ(mesh.triangles[0], Eigen::Vector3i(0, 1, 2));
}

constexpr std::string_view kAscii =
    "solid two facets\n"
    "  facet normal 0 0 1\n"
    "    outer loop\n"
    "      vertex 0 0 0\n"
    "      vertex 1 0 0\n"
    "      vertex 1 1 0\n"
    "    endloop\n"
    "  endfacet\n"
    "  FACET NORMAL 0 0 1\n"  // some writers use capitals
    "    OUTER LOOP\n"
    "      VERTEX 0 0 0\n"
    "      VERTEX 1 1 0\n"
    "      VERTEX 0 1 -0.5e1\n"
    "    ENDLOOP\n"
    "  ENDFACET\n"
    "endsolid two facets\n";

TEST(DecodeStl, AsciiSharesEqualPositions) {
  const TriangleMesh mesh = DecodeStl(Bytes(kAscii), "a.stl");
  ASSERT_EQ(mesh.vertices.size(), 4u);
  EXPECT_EQ(mesh.vertices[3], Eigen::Vector3d(0, 1, -5));
  ASSERT_EQ(mesh.triangles.size(), 2u);
  EXPECT_EQ(mesh.triangles[0], Eigen::Vector3i(0, 1, 2));
  EXPECT_EQ(mesh.triangles[1], Eigen::Vector3i(0, 2, 3));
}

TEST(DecodeStl, AsciiGarbageNamesItsLine) {
  std::string text(kAscii);
  text.replace(text.find("1 1 0\n    endloop"), 5, "1 1 q");
  try {
    DecodeStl(Bytes(text), "g.stl");
    FAIL();
  } catch (const IoError& e) {
    EXPECT_EQ(e.offset(), text.find(" q") + 1);
    EXPECT_THAT(e.what(), HasSubstr("line 6: expected a vertex coordinate, found 'q'"));
  }
}

TEST(DecodeStl, BinarySizeMismatchIsAnError) {
  std::vector<std::uint8_t> bytes = EncodeStl(Tetrahedron());
  bytes.push_back(0);
  try {
    DecodeStl(bytes, "m.stl");
    FAIL();
  } catch (const IoError& e) {
    EXPECT_EQ(e.offset(), 80u);
    EXPECT_THAT(e.what(), HasSubstr("expected 84 + 50 * 4 = 284 bytes, found 285"));
  }
  bytes.resize(100);  // truncated, and a "solid" header does not make it ASCII
  std::copy_n("solid", 5, bytes.begin());
  EXPECT_THROW(DecodeStl(bytes, "m.stl"), IoError);
  EXPECT_THROW(DecodeStl(Bytes("short"), "m.stl"), IoError);
}

}  // namespace
}  // namespace tofnav
