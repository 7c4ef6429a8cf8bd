// SPDX-License-Identifier: BSD-3-Clause
#include "tofnav/mesh/mesh_io.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <string>

#include "tofnav/core/require.hpp"
#include "tofnav/io/file.hpp"
#include "tofnav/io/io_error.hpp"

namespace tofnav {
namespace {

using ::testing::HasSubstr;

std::filesystem::path TempDir() {
  auto dir =
      std::filesystem::temp_directory_path() / ("tofnav_mesh_test_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  return dir;
}

/// Two triangles with every attribute; all values are exact floats.
TriangleMesh Square() {
  TriangleMesh mesh;
  mesh.vertices = {{-50.5, -50.5, 100}, {50.5, -50.5, 100}, {50.5, 50.5, 100.25f}, {0, 50.5, 0.1f}};
  mesh.vertex_normals = {{0, 0, -1}, {0, 0.6f, -0.8f}, {0, 0, -1}, {1, 0, 0}};
  mesh.vertex_colors = {Rgb8(255, 0, 0), Rgb8(0, 255, 0), Rgb8(0, 0, 255), Rgb8(9, 99, 199)};
  mesh.vertex_scalars = {0.25f, -0.5f, 1e-3f, 42.f};
  mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
  return mesh;
}

TEST(WriteMesh, PlyRoundTripThroughFilesInBothEncodings) {
  const TriangleMesh mesh = Square();
  for (const bool binary : {true, false}) {
    const auto path = TempDir() / (binary ? "square_binary.PLY" : "square_ascii.ply");
    WriteMesh(path, mesh, {.binary = binary});
    const TriangleMesh back = ReadMesh(path);
    EXPECT_EQ(back.vertices, mesh.vertices);
    EXPECT_EQ(back.vertex_normals, mesh.vertex_normals);
    EXPECT_EQ(back.vertex_colors, mesh.vertex_colors);
    EXPECT_EQ(back.vertex_scalars, mesh.vertex_scalars);  // written as "error_mm", read back
    EXPECT_EQ(back.triangles, mesh.triangles);
  }
}

TEST(WriteMesh, StlKeepsPositionsAndTriangles) {
  const auto path = TempDir() / "square.Stl";
  WriteMesh(path, Square());
  const TriangleMesh back = ReadMesh(path);
  EXPECT_EQ(back.vertices, Square().vertices);  // first-use order equals the original order
  EXPECT_EQ(back.triangles, Square().triangles);
  EXPECT_TRUE(back.vertex_normals.empty());
}

TEST(WriteMesh, ObjKeepsPositionsNormalsColours) {
  const auto path = TempDir() / "square.obj";
  WriteMesh(path, Square());
  const TriangleMesh back = ReadMesh(path);
  EXPECT_EQ(back.vertices, Square().vertices);
  EXPECT_EQ(back.vertex_normals, Square().vertex_normals);
  EXPECT_EQ(back.vertex_colors, Square().vertex_colors);
  EXPECT_EQ(back.triangles, Square().triangles);
  EXPECT_TRUE(back.vertex_scalars.empty());  // OBJ has no scalars
}

TEST(WritePointCloud, PlyWithoutFacesRoundTrips) {
  const TriangleMesh square = Square();
  PointCloud cloud{square.vertices, square.vertex_normals, square.vertex_colors,
                   square.vertex_scalars};
  const auto path = TempDir() / "cloud.ply";
  WritePointCloud(path, cloud, {.binary = false, .scalar_name = "intensity"});
  const std::vector<std::uint8_t> bytes = ReadFileBytes(path);
  EXPECT_THAT(std::string(bytes.begin(), bytes.end()), ::testing::Not(HasSubstr("element face")));
  const PointCloud back = ReadPointCloud(path);
  EXPECT_EQ(back.points, cloud.points);
  EXPECT_EQ(back.normals, cloud.normals);
  EXPECT_EQ(back.colors, cloud.colors);
  EXPECT_EQ(back.scalars, cloud.scalars);
  EXPECT_THROW(WritePointCloud(TempDir() / "cloud.stl", cloud), IoError);
}

TEST(ReadPointCloud, TakesTheVerticesOfAnyMeshFormat) {
  const auto path = TempDir() / "cloud_source.stl";
  WriteMesh(path, Square());
  EXPECT_EQ(ReadPointCloud(path).points, Square().vertices);
}

TEST(ReadMesh, UnknownExtensionAndMissingFileAreIoErrors) {
  try {
    ReadMesh(TempDir() / "mesh.vtk");
    FAIL();
  } catch (const IoError& e) {
    EXPECT_THAT(e.what(), HasSubstr("unknown mesh extension '.vtk'"));
  }
  EXPECT_THROW(WriteMesh(TempDir() / "mesh", Square()), IoError);
  EXPECT_THROW(ReadMesh(TempDir() / "absent.ply"), IoError);
}

TEST(WriteMesh, RejectsBadOptionsAndInconsistentMeshes) {
  EXPECT_THROW(WriteMesh(TempDir() / "o.ply", Square(), {.scalar_name = "two words"}),
               PreconditionError);
  EXPECT_THROW(WriteMesh(TempDir() / "o.ply", Square(), {.scalar_name = "red"}), PreconditionError);
  TriangleMesh broken = Square();
  broken.triangles.emplace_back(0, 1, 4);
  EXPECT_THROW(WriteMesh(TempDir() / "o.obj", broken), PreconditionError);
  EXPECT_FALSE(std::filesystem::exists(TempDir() / "o.obj"));
}

}  // namespace
}  // namespace tofnav
