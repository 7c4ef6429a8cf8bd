// SPDX-License-Identifier: BSD-3-Clause
// Wavefront OBJ: v (with optional colours), vn and polygon faces; everything else is skipped.
#include <array>
#include <cmath>
#include <limits>
#include <optional>

#include "tofnav/core/require.hpp"
#include "tofnav/io/mesh_text.hpp"
#include "tofnav/mesh/mesh_io.hpp"

namespace tofnav {
namespace {

struct ObjReader {
  explicit ObjReader(TextScanner& text) : scanner(text) {}

  TextScanner& scanner;
  TriangleMesh mesh;
  Points3d normals;          // the vn lines
  std::vector<Rgb8> colors;  // per v line, while every v line has colours
  bool all_colored = true;
  bool corners_have_normals = false;
  std::vector<int> first_normal;     // per vertex: first vn index its corners name, or -1
  std::vector<bool> normal_differs;  // per vertex: its corners name different normals
  Points3d normal_sums;              // per vertex: sum of the normals its corners name

  // Numbers on the rest of the line.
  std::size_t Numbers(std::span<double> out, std::string_view what) {
    std::size_t n = 0;
    while (const auto token = scanner.TokenOnLine()) {
      if (token->starts_with('#')) break;  // a trailing comment
      if (n == out.size())
        scanner.Fail("more than " + std::to_string(out.size()) + " numbers " + std::string(what));
      if (!ParseNumber(*token, out[n])) scanner.FailExpected("a number " + std::string(what));
      ++n;
    }
    return n;
  }

  void Vertex() {
    std::array<double, 7> values{};
    const std::size_t n = Numbers(values, "on a 'v' line");
    if (n < 3 || n == 5) scanner.Fail("expected 'v x y z [w]' or 'v x y z r g b'");
    if (mesh.vertices.size() >= static_cast<std::size_t>(std::numeric_limits<int>::max())) {
      scanner.Fail("more than 2^31 - 1 vertices");
    }
    mesh.vertices.emplace_back(values[0], values[1], values[2]);
    all_colored = all_colored && n >= 6;
    if (all_colored)
      colors.emplace_back(Channel(values[3]), Channel(values[4]), Channel(values[5]));
    first_normal.push_back(-1);
    normal_differs.push_back(false);
    normal_sums.push_back(Eigen::Vector3d::Zero());
  }

  void Normal() {
    std::array<double, 3> values{};
    if (Numbers(values, "on a 'vn' line") != 3) scanner.Fail("expected 'vn x y z'");
    if (normals.size() >= static_cast<std::size_t>(std::numeric_limits<int>::max())) {
      scanner.Fail("more than 2^31 - 1 normals");
    }
    normals.emplace_back(values[0], values[1], values[2]);
  }

  void Face() {
    std::vector<int> corners;
    while (const auto token = scanner.TokenOnLine()) {
      if (token->starts_with('#')) break;
      corners.push_back(Corner(*token));
    }
    if (corners.size() < 3) {
      scanner.Fail("a face with " + std::to_string(corners.size()) +
                   " corners, expected at least 3");
    }
    for (std::size_t k = 1; k + 1 < corners.size(); ++k) {  // fan around the first corner
      mesh.triangles.emplace_back(corners[0], corners[k], corners[k + 1]);
    }
  }

  /// "v", "v/vt", "v//vn" or "v/vt/vn"; indices from 1, or negative counting back from the last.
  int Corner(std::string_view token) {
    std::array<std::string_view, 3> parts{};
    std::size_t part = 0;
    for (std::size_t start = 0;;) {
      const std::size_t slash = token.find('/', start);
      if (part == parts.size()) scanner.FailExpected("a face corner v, v/vt, v//vn or v/vt/vn");
      parts[part++] = token.substr(start, slash == std::string_view::npos ? slash : slash - start);
      if (slash == std::string_view::npos) break;
      start = slash + 1;
    }
    const int vertex = Resolve(parts[0], mesh.vertices.size(), "vertex");
    if (!parts[2].empty()) {
      const int normal = Resolve(parts[2], normals.size(), "normal");
      corners_have_normals = true;
      const auto v = static_cast<std::size_t>(vertex);
      if (first_normal[v] < 0) first_normal[v] = normal;
      normal_differs[v] =
          normal_differs[v] || normals[static_cast<std::size_t>(normal)] !=
                                   normals[static_cast<std::size_t>(first_normal[v])];
      normal_sums[v] += normals[static_cast<std::size_t>(normal)];
    }
    return vertex;
  }

  int Resolve(std::string_view text, std::size_t count, const char* what) {
    std::int64_t index = 0;
    if (!ParseNumber(text, index)) scanner.FailExpected(std::string("a ") + what + " index");
    const auto n = static_cast<std::int64_t>(count);
    if (index > 0 && index <= n) return static_cast<int>(index - 1);
    if (index < 0 && index >= -n) return static_cast<int>(n + index);
    scanner.Fail(std::string(what) + " index " + std::to_string(index) +
                 " out of range: " + std::to_string(count) + " defined so far");
  }

  static std::uint8_t Channel(double fraction) {
    const double scaled = fraction * 255.0;
    if (!(scaled > 0.0)) return 0;
    return scaled >= 255.0 ? 255 : static_cast<std::uint8_t>(std::lround(scaled));
  }

  /// Per-vertex normals, kept only when every vertex has one.
  void FinishNormals() {
    const std::size_t n = mesh.vertices.size();
    if (!corners_have_normals) {
      if (!normals.empty() && normals.size() == n) mesh.vertex_normals = normals;  // a point list
      return;
    }
    for (const int first : first_normal) {
      if (first < 0) return;
    }
    mesh.vertex_normals.resize(n);
    for (std::size_t v = 0; v < n; ++v) {
      mesh.vertex_normals[v] = normal_differs[v]
                                   ? Eigen::Vector3d(normal_sums[v].stableNormalized())
                                   : normals[static_cast<std::size_t>(first_normal[v])];
    }
  }
};

}  // namespace

TriangleMesh DecodeObj(std::span<const std::uint8_t> bytes, const std::filesystem::path& source) {
  TextScanner scanner(bytes, source);
  ObjReader reader(scanner);
  while (!scanner.AtEnd()) {
    const auto keyword = scanner.TokenOnLine();
    if (keyword == "v") {
      reader.Vertex();
    } else if (keyword == "vn") {
      reader.Normal();
    } else if (keyword == "f") {
      reader.Face();
    }
    scanner.SkipLine();  // vt, o, g, s, l, usemtl, mtllib, comments, blank lines
  }
  reader.FinishNormals();
  if (reader.all_colored && !reader.mesh.vertices.empty()) {
    reader.mesh.vertex_colors = std::move(reader.colors);
  }
  return std::move(reader.mesh);
}

std::string EncodeObj(const TriangleMesh& mesh) {
  mesh.CheckConsistent();
  std::string out = "# tofnav OBJ, units mm\n";
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
    out += 'v';
    for (int k = 0; k < 3; ++k) AppendNumber(out += ' ', mesh.vertices[i][k]);
    if (!mesh.vertex_colors.empty()) {
      for (int k = 0; k < 3; ++k) AppendNumber(out += ' ', mesh.vertex_colors[i][k] / 255.0);
    }
    out += '\n';
  }
  for (const Eigen::Vector3d& normal : mesh.vertex_normals) {
    out += "vn";
    for (int k = 0; k < 3; ++k) AppendNumber(out += ' ', normal[k]);
    out += '\n';
  }
  const bool with_normals = !mesh.vertex_normals.empty();
  for (const Eigen::Vector3i& t : mesh.triangles) {
    out += 'f';
    for (int k = 0; k < 3; ++k) {
      const std::string index = std::to_string(t[k] + 1);  // OBJ counts from 1
      out += ' ' + index + (with_normals ? "//" + index : "");
    }
    out += '\n';
  }
  return out;
}

}  // namespace tofnav
