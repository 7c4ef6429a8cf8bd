// SPDX-License-Identifier: BSD-3-Clause
// Mesh and point cloud files: the format is chosen by extension; bytes go through file.hpp.
#include "tofnav/mesh/mesh_io.hpp"

#include <array>
#include <string_view>

#include "tofnav/core/require.hpp"
#include "tofnav/io/file.hpp"
#include "tofnav/io/io_error.hpp"
#include "tofnav/io/mesh_text.hpp"

namespace tofnav {
namespace {

enum class MeshFormat { kPly, kStl, kObj };

MeshFormat FormatOf(const std::filesystem::path& path) {
  const std::string extension = path.extension().string();
  if (EqualsIgnoreCase(extension, ".ply")) return MeshFormat::kPly;
  if (EqualsIgnoreCase(extension, ".stl")) return MeshFormat::kStl;
  if (EqualsIgnoreCase(extension, ".obj")) return MeshFormat::kObj;
  throw IoError(path, std::nullopt,
                "unknown mesh extension " + Quote(extension) + ", expected .ply, .stl or .obj");
}

}  // namespace

void MeshWriteOptions::Check() const {
  constexpr std::array<std::string_view, 9> kTaken = {"x",  "y",   "z",     "nx",  "ny",
                                                      "nz", "red", "green", "blue"};
  Require(!scalar_name.empty(), "MeshWriteOptions::scalar_name is empty");
  for (const char c : scalar_name) {
    Require(c > ' ' && c < 0x7f,
            "MeshWriteOptions::scalar_name must be printable ASCII, no spaces");
  }
  for (const std::string_view taken : kTaken) {
    Require(scalar_name != taken, "MeshWriteOptions::scalar_name names another PLY property");
  }
}

TriangleMesh ReadMesh(const std::filesystem::path& path, const MeshReadOptions& options) {
  const MeshFormat format = FormatOf(path);
  const std::vector<std::uint8_t> bytes = ReadFileBytes(path);
  switch (format) {
    case MeshFormat::kPly:
      return DecodePly(bytes, path, options);
    case MeshFormat::kStl:
      return DecodeStl(bytes, path);
    case MeshFormat::kObj:
      return DecodeObj(bytes, path);
  }
  throw IoError(path, std::nullopt, "unknown mesh format");
}

void WriteMesh(const std::filesystem::path& path, const TriangleMesh& mesh,
               const MeshWriteOptions& options) {
  switch (FormatOf(path)) {
    case MeshFormat::kPly:
      WriteFileAtomically(path, EncodePly(mesh, options));
      return;
    case MeshFormat::kStl:
      WriteFileAtomically(path, EncodeStl(mesh));
      return;
    case MeshFormat::kObj:
      WriteFileAtomically(path, EncodeObj(mesh));
      return;
  }
}

PointCloud ReadPointCloud(const std::filesystem::path& path, const MeshReadOptions& options) {
  TriangleMesh mesh = ReadMesh(path, options);
  PointCloud cloud;
  cloud.points = std::move(mesh.vertices);
  cloud.normals = std::move(mesh.vertex_normals);
  cloud.colors = std::move(mesh.vertex_colors);
  cloud.scalars = std::move(mesh.vertex_scalars);
  return cloud;
}

void WritePointCloud(const std::filesystem::path& path, const PointCloud& cloud,
                     const MeshWriteOptions& options) {
  if (FormatOf(path) != MeshFormat::kPly) {
    throw IoError(path, std::nullopt, "point clouds are written as .ply only");
  }
  WriteFileAtomically(path, EncodePly(cloud, options));
}

}  // namespace tofnav
