// SPDX-License-Identifier: BSD-3-Clause
// libFuzzer target: DecodePly on arbitrary bytes; whatever decodes must re-encode and decode again.
#include <cstdint>
#include <cstdlib>
#include <span>

#include "tofnav/io/io_error.hpp"
#include "tofnav/mesh/mesh_io.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  tofnav::TriangleMesh mesh;
  try {
    mesh = tofnav::DecodePly(std::span<const std::uint8_t>(data, size), "fuzz.ply");
  } catch (const tofnav::IoError&) {
    return 0;  // malformed input is expected to be refused
  }
  mesh.CheckConsistent();  // a decoded mesh is always consistent (throws, and so crashes, if not)
  const tofnav::TriangleMesh again = tofnav::DecodePly(tofnav::EncodePly(mesh), "again.ply");
  if (again.vertices.size() != mesh.vertices.size() || again.triangles != mesh.triangles ||
      again.vertex_colors != mesh.vertex_colors) {
    std::abort();
  }
  return 0;
}
