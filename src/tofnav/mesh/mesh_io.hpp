// SPDX-License-Identifier: BSD-3-Clause
// Triangle meshes and point clouds in PLY, STL and OBJ files; coordinates are mm, never converted.
#pragma once

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "tofnav/core/point_cloud.hpp"
#include "tofnav/core/triangle_mesh.hpp"

namespace tofnav {

struct MeshReadOptions {
  /// The PLY vertex property read into the scalars: the first present of this name, then
  /// "scalar", "quality", "error_mm", "value", "intensity" (non-list properties only).
  std::string scalar_name = "error_mm";
};

struct MeshWriteOptions {
  bool binary = true;  // PLY: binary_little_endian, else ascii. STL is always binary, OBJ text.
  std::string scalar_name = "error_mm";  // PLY name of the vertex scalars
  /// Throws PreconditionError unless scalar_name is a non-empty PLY word that is not already
  /// written (x, y, z, nx, ny, nz, red, green, blue).
  void Check() const;
};

/// Reads a mesh by extension (.ply, .stl, .obj, any case); IoError for anything else.
/// PLY: ascii, binary little- and big-endian; faces with n > 3 corners become triangle fans;
/// other elements and unused properties are skipped. Colours are uchar, or 0..1 floats (scaled).
/// STL: binary when its size is exactly 84 + 50 * count (even if it starts with "solid"), else
/// ASCII; equal positions are merged so the mesh stays indexed; facet normals are dropped.
/// OBJ: v (optionally v x y z r g b with 0..1 colours), vn, f with v, v/vt, v//vn, v/vt/vn and
/// negative (relative) indices, polygons as fans. A vertex's normal is the one its face corners
/// name (the normalised mean when they differ); normals are kept only if every vertex has one.
TriangleMesh ReadMesh(const std::filesystem::path& path, const MeshReadOptions& options = {});

/// Writes a mesh by extension. PLY: float x y z [nx ny nz] [uchar red green blue]
/// [float <scalar_name>], face list uchar int vertex_indices. STL: binary, positions only.
/// OBJ: v [r g b], vn, f v//vn, with shortest round-trip decimals (exact for doubles).
/// Throws PreconditionError for an inconsistent mesh, IoError when writing fails.
void WriteMesh(const std::filesystem::path& path, const TriangleMesh& mesh,
               const MeshWriteOptions& options = {});

/// The vertices (with their attributes) of any mesh file ReadMesh accepts.
PointCloud ReadPointCloud(const std::filesystem::path& path, const MeshReadOptions& options = {});

/// Writes a PLY point cloud (vertex element only); IoError for other extensions.
void WritePointCloud(const std::filesystem::path& path, const PointCloud& cloud,
                     const MeshWriteOptions& options = {});

/// In-memory codecs behind the functions above; `source` only names the data in IoError.
TriangleMesh DecodePly(std::span<const std::uint8_t> bytes, const std::filesystem::path& source,
                       const MeshReadOptions& options = {});
TriangleMesh DecodeStl(std::span<const std::uint8_t> bytes, const std::filesystem::path& source);
TriangleMesh DecodeObj(std::span<const std::uint8_t> bytes, const std::filesystem::path& source);
std::vector<std::uint8_t> EncodePly(const TriangleMesh& mesh, const MeshWriteOptions& options = {});
std::vector<std::uint8_t> EncodePly(const PointCloud& cloud, const MeshWriteOptions& options = {});
std::vector<std::uint8_t> EncodeStl(const TriangleMesh& mesh);
std::string EncodeObj(const TriangleMesh& mesh);

}  // namespace tofnav
