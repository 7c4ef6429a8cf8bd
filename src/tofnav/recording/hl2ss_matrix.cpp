// SPDX-License-Identifier: BSD-3-Clause
// hl2ss DirectX float4x4 matrices (row-vector convention, metres) <-> Rigid3d (column-vector, mm).
#include "tofnav/recording/hl2ss_matrix.hpp"

#include <bit>
#include <cstring>
#include <sstream>

#include "tofnav/core/require.hpp"
#include "tofnav/core/units.hpp"
#include "tofnav/io/io_error.hpp"

namespace tofnav {
namespace {

// Device matrices are f32 built from a quaternion: their rotation blocks are orthonormal to about
// 1e-7, so anything beyond this is a broken or non-rigid matrix, not rounding.
constexpr double kRigidTolerance = 1e-4;

static_assert(std::endian::native == std::endian::little, "hl2ss matrices are little-endian f32");

}  // namespace

DirectXMatrix DirectXFromBytes(std::span<const std::uint8_t, 64> bytes) {
  DirectXMatrix matrix;
  std::memcpy(matrix.data(), bytes.data(), bytes.size());
  return matrix;
}

std::array<std::uint8_t, 64> BytesFromDirectX(const DirectXMatrix& matrix) {
  std::array<std::uint8_t, 64> bytes;
  std::memcpy(bytes.data(), matrix.data(), bytes.size());
  return bytes;
}

Rigid3d RigidFromDirectX(const DirectXMatrix& matrix, const std::filesystem::path& source,
                         std::uint64_t offset) {
  // Element (row r, column c) of M is matrix[4 r + c]; the column-vector form is M^T.
  Eigen::Matrix4d b_from_a;
  for (Eigen::Index r = 0; r < 4; ++r) {
    for (Eigen::Index c = 0; c < 4; ++c) {
      b_from_a(c, r) = static_cast<double>(matrix[static_cast<std::size_t>(4 * r + c)]);
    }
  }
  b_from_a.topRightCorner<3, 1>() *= kMmPerMetre;
  // FromMatrix checks the rotation block and the last row; the translation must be finite too.
  if (b_from_a.allFinite()) {
    try {
      return Rigid3d::FromMatrix(b_from_a, kRigidTolerance);
    } catch (const PreconditionError&) {  // reported below with the file and offset
    }
  }
  std::ostringstream text;
  text << "expected a rigid 4x4 matrix (row-vector convention), found";
  for (const float value : matrix) text << ' ' << value;
  throw IoError(source, offset, text.str());
}

DirectXMatrix DirectXFromRigid(const Rigid3d& b_from_a) {
  Eigen::Matrix4d column_form = b_from_a.ToMatrix();
  column_form.topRightCorner<3, 1>() /= kMmPerMetre;
  DirectXMatrix matrix;
  for (Eigen::Index r = 0; r < 4; ++r) {
    for (Eigen::Index c = 0; c < 4; ++c) {
      matrix[static_cast<std::size_t>(4 * r + c)] = static_cast<float>(column_form(c, r));
    }
  }
  return matrix;
}

}  // namespace tofnav
