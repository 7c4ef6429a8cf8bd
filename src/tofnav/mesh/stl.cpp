// SPDX-License-Identifier: BSD-3-Clause
// STL: binary (80-byte header, u32 count, 50 bytes per facet) and ASCII, merged into an indexed
// mesh.
#include <array>
#include <bit>
#include <cstring>
#include <limits>
#include <unordered_map>

#include "tofnav/core/require.hpp"
#include "tofnav/io/binary.hpp"
#include "tofnav/io/io_error.hpp"
#include "tofnav/io/mesh_text.hpp"
#include "tofnav/mesh/mesh_io.hpp"

namespace tofnav {
namespace {

constexpr std::size_t kHeaderBytes = 80;
constexpr std::size_t kFacetBytes = 50;  // normal, 3 vertices (12 floats), u16 attribute

using PositionKey = std::array<std::uint32_t, 3>;  // float bits, -0 folded into +0

struct PositionKeyHash {
  std::size_t operator()(const PositionKey& key) const {
    std::uint64_t h = 1469598103934665603ull;  // FNV-1a over the three words
    for (const std::uint32_t word : key) h = (h ^ word) * 1099511628211ull;
    return static_cast<std::size_t>(h);
  }
};

/// Builds an indexed mesh from facet corners, one vertex per distinct exact position.
class MeshBuilder {
 public:
  int Vertex(const std::array<float, 3>& position) {
    PositionKey key;
    for (std::size_t k = 0; k < 3; ++k) key[k] = std::bit_cast<std::uint32_t>(position[k] + 0.0f);
    const auto [it, inserted] = index_.try_emplace(key, static_cast<int>(mesh_.vertices.size()));
    if (inserted) mesh_.vertices.emplace_back(position[0], position[1], position[2]);
    return it->second;
  }
  void Facet(const std::array<std::array<float, 3>, 3>& corners) {
    const int a = Vertex(corners[0]);  // in order: argument evaluation order is unspecified
    const int b = Vertex(corners[1]);
    const int c = Vertex(corners[2]);
    mesh_.triangles.emplace_back(a, b, c);
  }
  TriangleMesh& mesh() { return mesh_; }

 private:
  TriangleMesh mesh_;
  std::unordered_map<PositionKey, int, PositionKeyHash> index_;
};

TriangleMesh DecodeBinary(std::span<const std::uint8_t> bytes, const std::filesystem::path& path,
                          std::uint32_t count) {
  ByteReader reader(bytes, path);
  reader.Skip(kHeaderBytes + 4, "STL header and facet count");
  MeshBuilder builder;
  builder.mesh().triangles.reserve(count);
  for (std::uint32_t f = 0; f < count; ++f) {
    reader.Skip(12, "STL facet normal");
    std::array<std::array<float, 3>, 3> corners{};
    for (auto& corner : corners) {
      for (float& value : corner) value = reader.Le<float>("STL vertex");
    }
    reader.Skip(2, "STL attribute byte count");
    builder.Facet(corners);
  }
  return std::move(builder.mesh());
}

void ExpectKeyword(TextScanner& scanner, std::string_view keyword) {
  if (!EqualsIgnoreCase(scanner.Token(keyword), keyword)) scanner.FailExpected(keyword);
}

TriangleMesh DecodeAscii(std::span<const std::uint8_t> bytes, const std::filesystem::path& path) {
  TextScanner scanner(bytes, path);
  ExpectKeyword(scanner, "solid");
  scanner.SkipLine();  // the solid's name
  MeshBuilder builder;
  while (true) {
    const std::string_view keyword = scanner.Token("'facet' or 'endsolid'");
    if (EqualsIgnoreCase(keyword, "endsolid")) {
      scanner.SkipLine();
      const auto next = scanner.NextToken();
      if (!next) break;
      if (!EqualsIgnoreCase(*next, "solid")) scanner.FailExpected("'solid' or the end of the file");
      scanner.SkipLine();  // several solids in one file
      continue;
    }
    if (!EqualsIgnoreCase(keyword, "facet")) scanner.FailExpected("'facet' or 'endsolid'");
    ExpectKeyword(scanner, "normal");
    for (int k = 0; k < 3; ++k) scanner.Number<float>("a facet normal component");
    ExpectKeyword(scanner, "outer");
    ExpectKeyword(scanner, "loop");
    std::array<std::array<float, 3>, 3> corners{};
    for (auto& corner : corners) {
      ExpectKeyword(scanner, "vertex");
      for (float& value : corner) value = scanner.Number<float>("a vertex coordinate");
    }
    ExpectKeyword(scanner, "endloop");
    ExpectKeyword(scanner, "endfacet");
    builder.Facet(corners);
  }
  return std::move(builder.mesh());
}

bool StartsWithSolid(std::span<const std::uint8_t> bytes) {
  std::size_t i = 0;
  while (i < bytes.size() &&
         (bytes[i] == ' ' || bytes[i] == '\t' || bytes[i] == '\r' || bytes[i] == '\n')) {
    ++i;
  }
  constexpr std::string_view kSolid = "solid";
  if (bytes.size() - i < kSolid.size()) return false;
  const std::string_view head(reinterpret_cast<const char*>(bytes.data()) + i, kSolid.size());
  return EqualsIgnoreCase(head, kSolid);
}

}  // namespace

TriangleMesh DecodeStl(std::span<const std::uint8_t> bytes, const std::filesystem::path& source) {
  // A binary file is recognised by its exact size, since many binary headers also start "solid".
  std::string size_problem =
      "expected at least 84 bytes (binary STL header and facet count) or "
      "an ASCII STL starting with 'solid', found " +
      std::to_string(bytes.size()) + " bytes";
  std::uint64_t size_problem_offset = bytes.size();
  if (bytes.size() >= kHeaderBytes + 4) {
    ByteReader reader(bytes.subspan(kHeaderBytes), source, kHeaderBytes);
    const std::uint32_t count = reader.Le<std::uint32_t>("STL facet count");
    const std::uint64_t expected = kHeaderBytes + 4 + std::uint64_t{count} * kFacetBytes;
    if (expected == bytes.size()) return DecodeBinary(bytes, source, count);
    size_problem = "binary STL with " + std::to_string(count) + " facets: expected 84 + 50 * " +
                   std::to_string(count) + " = " + std::to_string(expected) + " bytes, found " +
                   std::to_string(bytes.size());
    size_problem_offset = kHeaderBytes;
  }
  if (!StartsWithSolid(bytes)) throw IoError(source, size_problem_offset, size_problem);
  try {
    return DecodeAscii(bytes, source);
  } catch (const IoError& error) {
    // Neither reading fits: keep the ASCII error and add why it is not binary either.
    std::string message = error.what();
    const std::string prefix =
        source.string() + ": at byte " + std::to_string(error.offset().value_or(0)) + ": ";
    if (message.starts_with(prefix)) message.erase(0, prefix.size());
    throw IoError(
        source, error.offset(),
        message + " (read as ASCII since it starts with 'solid'; as binary: " + size_problem + ")");
  }
}

std::vector<std::uint8_t> EncodeStl(const TriangleMesh& mesh) {
  mesh.CheckConsistent();
  Require(mesh.triangles.size() <= std::numeric_limits<std::uint32_t>::max(),
          "STL: more than 2^32 - 1 triangles");
  ByteWriter out;
  out.bytes().reserve(kHeaderBytes + 4 + kFacetBytes * mesh.triangles.size());
  std::string header = "tofnav binary STL, units mm";  // must not start with "solid"
  header.resize(kHeaderBytes, ' ');
  out.Text(header);
  out.Le(static_cast<std::uint32_t>(mesh.triangles.size()));
  for (const Eigen::Vector3i& t : mesh.triangles) {
    std::array<Eigen::Vector3d, 3> corners;
    for (int c = 0; c < 3; ++c)
      corners[static_cast<std::size_t>(c)] = mesh.vertices[static_cast<std::size_t>(t[c])];
    const Eigen::Vector3d normal =
        (corners[1] - corners[0]).cross(corners[2] - corners[0]).stableNormalized();
    for (int k = 0; k < 3; ++k) out.Le(NarrowToFloat(normal[k]));
    for (const Eigen::Vector3d& corner : corners) {
      for (int k = 0; k < 3; ++k) out.Le(NarrowToFloat(corner[k]));
    }
    out.Le(std::uint16_t{0});
  }
  return out.Release();
}

}  // namespace tofnav
