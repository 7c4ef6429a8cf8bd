// SPDX-License-Identifier: BSD-3-Clause
// PLY encoding: float positions, optional normals, uchar colours, a float scalar; int faces.
#include <limits>

#include "tofnav/core/require.hpp"
#include "tofnav/io/binary.hpp"
#include "tofnav/io/mesh_text.hpp"
#include "tofnav/mesh/mesh_io.hpp"

namespace tofnav {
namespace {

struct VertexData {
  const Points3d& positions;
  const Points3d& normals;
  const std::vector<Rgb8>& colors;
  const std::vector<float>& scalars;
};

std::string Header(const VertexData& vertices, const std::vector<Eigen::Vector3i>* triangles,
                   const MeshWriteOptions& options) {
  std::string header = "ply\nformat ";
  header += options.binary ? "binary_little_endian 1.0\n" : "ascii 1.0\n";
  header += "comment tofnav, units mm\n";
  header += "element vertex " + std::to_string(vertices.positions.size()) + "\n";
  header += "property float x\nproperty float y\nproperty float z\n";
  if (!vertices.normals.empty())
    header += "property float nx\nproperty float ny\nproperty float nz\n";
  if (!vertices.colors.empty()) {
    header += "property uchar red\nproperty uchar green\nproperty uchar blue\n";
  }
  if (!vertices.scalars.empty()) header += "property float " + options.scalar_name + "\n";
  if (triangles != nullptr) {
    header += "element face " + std::to_string(triangles->size()) + "\n";
    header += "property list uchar int vertex_indices\n";
  }
  return header + "end_header\n";
}

void AppendBinary(const VertexData& vertices, const std::vector<Eigen::Vector3i>* triangles,
                  ByteWriter& out) {
  for (std::size_t i = 0; i < vertices.positions.size(); ++i) {
    for (int k = 0; k < 3; ++k) out.Le(NarrowToFloat(vertices.positions[i][k]));
    if (!vertices.normals.empty()) {
      for (int k = 0; k < 3; ++k) out.Le(NarrowToFloat(vertices.normals[i][k]));
    }
    if (!vertices.colors.empty()) {
      for (int k = 0; k < 3; ++k) out.Le(vertices.colors[i][k]);
    }
    if (!vertices.scalars.empty()) out.Le(vertices.scalars[i]);
  }
  if (triangles == nullptr) return;
  for (const Eigen::Vector3i& t : *triangles) {
    out.Le(std::uint8_t{3});
    for (int k = 0; k < 3; ++k) out.Le(static_cast<std::int32_t>(t[k]));
  }
}

void AppendVector(std::string& out, const Eigen::Vector3d& v) {
  for (int k = 0; k < 3; ++k) {
    out += ' ';
    AppendNumber(out, NarrowToFloat(v[k]));
  }
}

void AppendAscii(const VertexData& vertices, const std::vector<Eigen::Vector3i>* triangles,
                 std::string& out) {
  for (std::size_t i = 0; i < vertices.positions.size(); ++i) {
    std::string line;
    AppendVector(line, vertices.positions[i]);
    if (!vertices.normals.empty()) AppendVector(line, vertices.normals[i]);
    if (!vertices.colors.empty()) {
      for (int k = 0; k < 3; ++k) line += ' ' + std::to_string(vertices.colors[i][k]);
    }
    if (!vertices.scalars.empty()) {
      line += ' ';
      AppendNumber(line, vertices.scalars[i]);
    }
    out.append(line, 1);  // drop the leading separator
    out += '\n';
  }
  if (triangles == nullptr) return;
  for (const Eigen::Vector3i& t : *triangles) {
    out += "3 " + std::to_string(t[0]) + ' ' + std::to_string(t[1]) + ' ' + std::to_string(t[2]);
    out += '\n';
  }
}

std::vector<std::uint8_t> Encode(const VertexData& vertices,
                                 const std::vector<Eigen::Vector3i>* triangles,
                                 const MeshWriteOptions& options) {
  options.Check();
  Require(vertices.positions.size() <= static_cast<std::size_t>(std::numeric_limits<int>::max()),
          "PLY: more than 2^31 - 1 vertices");
  const std::string header = Header(vertices, triangles, options);
  if (!options.binary) {
    std::string text = header;
    AppendAscii(vertices, triangles, text);
    return {text.begin(), text.end()};
  }
  ByteWriter out;
  const std::size_t vertex_bytes = 12 + (vertices.normals.empty() ? 0 : 12) +
                                   (vertices.colors.empty() ? 0 : 3) +
                                   (vertices.scalars.empty() ? 0 : 4);
  out.bytes().reserve(header.size() + vertex_bytes * vertices.positions.size() +
                      (triangles != nullptr ? 13 * triangles->size() : 0));
  out.Text(header);
  AppendBinary(vertices, triangles, out);
  return out.Release();
}

}  // namespace

std::vector<std::uint8_t> EncodePly(const TriangleMesh& mesh, const MeshWriteOptions& options) {
  mesh.CheckConsistent();
  return Encode({mesh.vertices, mesh.vertex_normals, mesh.vertex_colors, mesh.vertex_scalars},
                &mesh.triangles, options);
}

std::vector<std::uint8_t> EncodePly(const PointCloud& cloud, const MeshWriteOptions& options) {
  cloud.CheckConsistent();
  return Encode({cloud.points, cloud.normals, cloud.colors, cloud.scalars}, nullptr, options);
}

}  // namespace tofnav
