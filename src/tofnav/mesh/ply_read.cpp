// SPDX-License-Identifier: BSD-3-Clause
// PLY decoding: vertices with normals, colours and one scalar; polygon faces as triangle fans.
#include <array>
#include <cmath>
#include <limits>
#include <string_view>

#include "tofnav/io/io_error.hpp"
#include "tofnav/mesh/mesh_io.hpp"
#include "tofnav/mesh/ply_header.hpp"
#include "tofnav/mesh/ply_source.hpp"

namespace tofnav {
namespace {

// Where each vertex property's value goes; kUnused collects values that are read and dropped.
constexpr std::size_t kX = 0, kY = 1, kZ = 2, kNx = 3, kNy = 4, kNz = 5, kRed = 6, kGreen = 7,
                      kBlue = 8, kScalar = 9, kUnused = 10;

struct VertexLayout {
  std::vector<std::size_t> slot_of_property;  // kUnused: read and dropped
  std::array<PlyType, 3> color_types{};
  bool normals = false;
  bool colors = false;
  bool scalars = false;
};

VertexLayout MakeVertexLayout(const PlyElement& element, const MeshReadOptions& options,
                              const std::filesystem::path& path) {
  constexpr std::array<std::string_view, kScalar> kNames = {"x",  "y",   "z",     "nx",  "ny",
                                                            "nz", "red", "green", "blue"};
  VertexLayout layout;
  layout.slot_of_property.assign(element.properties.size(), kUnused);
  std::array<bool, kUnused> found{};
  const auto assign = [&](std::string_view name, std::size_t slot) {
    for (std::size_t i = 0; i < element.properties.size() && !found[slot]; ++i) {
      const PlyProperty& p = element.properties[i];
      if (!p.is_list && p.name == name && layout.slot_of_property[i] == kUnused) {
        layout.slot_of_property[i] = slot;
        found[slot] = true;
        if (slot >= kRed && slot <= kBlue) layout.color_types[slot - kRed] = p.type;
      }
    }
  };
  for (std::size_t slot = kX; slot < kScalar; ++slot) assign(kNames[slot], slot);
  for (std::string_view name : {std::string_view(options.scalar_name), std::string_view("scalar"),
                                std::string_view("quality"), std::string_view("error_mm"),
                                std::string_view("value"), std::string_view("intensity")}) {
    assign(name, kScalar);
  }
  for (std::size_t slot = kX; slot <= kZ; ++slot) {
    if (!found[slot]) {
      throw IoError(path, element.header_offset,
                    "line " + std::to_string(element.header_line) +
                        ": element 'vertex' has no scalar property '" + std::string(kNames[slot]) +
                        "'");
    }
  }
  layout.normals = found[kNx] && found[kNy] && found[kNz];
  layout.colors = found[kRed] && found[kGreen] && found[kBlue];
  layout.scalars = found[kScalar];
  return layout;
}

/// 0..255 integers are taken as they are, floats as 0..1 fractions; both clamped, NaN as 0.
std::uint8_t ColorChannel(double value, PlyType type) {
  const double scaled = IsIntegerType(type) ? value : value * 255.0;
  if (!(scaled > 0.0)) return 0;
  if (scaled >= 255.0) return 255;
  return static_cast<std::uint8_t>(std::lround(scaled));
}

template <typename Source>
void ReadVertices(Source& source, const PlyElement& element, const VertexLayout& layout,
                  TriangleMesh& mesh) {
  source.CheckCount(element);
  const auto count = static_cast<std::size_t>(element.count);
  mesh.vertices.reserve(count);
  if (layout.normals) mesh.vertex_normals.reserve(count);
  if (layout.colors) mesh.vertex_colors.reserve(count);
  if (layout.scalars) mesh.vertex_scalars.reserve(count);
  std::array<double, kUnused + 1> values{};
  for (std::size_t v = 0; v < count; ++v) {
    for (std::size_t i = 0; i < element.properties.size(); ++i) {
      const PlyProperty& p = element.properties[i];
      if (p.is_list) {
        source.SkipItems(ListCount(source, p), p);
      } else {
        values[layout.slot_of_property[i]] = source.Value(p.type, p.what);
      }
    }
    mesh.vertices.emplace_back(values[kX], values[kY], values[kZ]);
    if (layout.normals) mesh.vertex_normals.emplace_back(values[kNx], values[kNy], values[kNz]);
    if (layout.colors) {
      mesh.vertex_colors.emplace_back(ColorChannel(values[kRed], layout.color_types[0]),
                                      ColorChannel(values[kGreen], layout.color_types[1]),
                                      ColorChannel(values[kBlue], layout.color_types[2]));
    }
    if (layout.scalars) mesh.vertex_scalars.push_back(NarrowToFloat(values[kScalar]));
  }
}

std::size_t FaceIndexProperty(const PlyElement& element, const std::filesystem::path& path) {
  for (std::size_t i = 0; i < element.properties.size(); ++i) {
    const PlyProperty& p = element.properties[i];
    if (!p.is_list || (p.name != "vertex_indices" && p.name != "vertex_index")) continue;
    if (!IsIntegerType(p.type)) {
      throw IoError(path, element.header_offset,
                    "line " + std::to_string(element.header_line) +
                        ": expected an integer item type for " + p.what);
    }
    return i;
  }
  throw IoError(path, element.header_offset,
                "line " + std::to_string(element.header_line) +
                    ": element 'face' has no list property 'vertex_indices' or 'vertex_index'");
}

template <typename Source>
void ReadFaces(Source& source, const PlyElement& element, std::size_t index_property,
               std::size_t vertex_count, TriangleMesh& mesh) {
  source.CheckCount(element);
  mesh.triangles.reserve(static_cast<std::size_t>(element.count));
  std::vector<int> corners;
  for (std::uint64_t f = 0; f < element.count; ++f) {
    for (std::size_t i = 0; i < element.properties.size(); ++i) {
      const PlyProperty& p = element.properties[i];
      if (i != index_property) {
        if (p.is_list) {
          source.SkipItems(ListCount(source, p), p);
        } else {
          source.Value(p.type, p.what);
        }
        continue;
      }
      const std::uint64_t n = ListCount(source, p);
      if (n < 3) source.Fail("a face with " + std::to_string(n) + " corners, expected at least 3");
      corners.clear();
      for (std::uint64_t k = 0; k < n; ++k) {
        const double index = source.Value(p.type, p.what);
        if (index < 0.0 || index >= static_cast<double>(vertex_count)) {
          source.Fail("vertex index " + std::to_string(static_cast<std::int64_t>(index)) +
                      " out of range [0, " + std::to_string(vertex_count) + ")");
        }
        corners.push_back(static_cast<int>(index));
      }
      for (std::size_t k = 1; k + 1 < corners.size(); ++k) {  // fan around the first corner
        mesh.triangles.emplace_back(corners[0], corners[k], corners[k + 1]);
      }
    }
  }
}

template <typename Source>
void SkipElement(Source& source, const PlyElement& element) {
  if (element.properties.empty()) return;
  source.CheckCount(element);
  for (std::uint64_t e = 0; e < element.count; ++e) {
    for (const PlyProperty& p : element.properties) {
      if (p.is_list) {
        source.SkipItems(ListCount(source, p), p);
      } else {
        source.Value(p.type, p.what);
      }
    }
  }
}

template <typename Source>
TriangleMesh ReadBody(Source& source, const PlyHeader& header, const std::filesystem::path& path,
                      const MeshReadOptions& options) {
  const PlyElement* vertex = nullptr;
  for (const PlyElement& element : header.elements) {
    if (element.name == "vertex") vertex = &element;
  }
  if (vertex == nullptr)
    throw IoError(path, std::nullopt, "the PLY header has no element 'vertex'");
  if (vertex->count > static_cast<std::uint64_t>(std::numeric_limits<int>::max())) {
    throw IoError(path, vertex->header_offset,
                  "line " + std::to_string(vertex->header_line) + ": more than 2^31 - 1 vertices");
  }
  const VertexLayout layout = MakeVertexLayout(*vertex, options, path);
  TriangleMesh mesh;
  for (const PlyElement& element : header.elements) {
    if (&element == vertex) {
      ReadVertices(source, element, layout, mesh);
    } else if (element.name == "face") {
      const std::size_t index_property = FaceIndexProperty(element, path);
      ReadFaces(source, element, index_property, static_cast<std::size_t>(vertex->count), mesh);
    } else {
      SkipElement(source, element);
    }
  }
  return mesh;
}

}  // namespace

TriangleMesh DecodePly(std::span<const std::uint8_t> bytes, const std::filesystem::path& source,
                       const MeshReadOptions& options) {
  TextScanner scanner(bytes, source);
  const PlyHeader header = ParsePlyHeader(scanner);
  if (header.format == PlyFormat::kAscii) {
    AsciiSource ascii(scanner);
    return ReadBody(ascii, header, source, options);
  }
  BinarySource binary(bytes, source, scanner.position(),
                      header.format == PlyFormat::kBinaryBigEndian);
  return ReadBody(binary, header, source, options);
}

}  // namespace tofnav
