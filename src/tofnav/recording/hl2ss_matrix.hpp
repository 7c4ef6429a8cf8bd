// SPDX-License-Identifier: BSD-3-Clause
// hl2ss DirectX float4x4 matrices (row-vector convention, metres) <-> Rigid3d (column-vector, mm).
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <span>

#include "tofnav/core/rigid3d.hpp"

namespace tofnav {

/// The 16 little-endian f32 of an hl2ss matrix in storage order (row-major m11..m44).
using DirectXMatrix = std::array<float, 16>;

/// Reads 64 little-endian bytes as a DirectXMatrix.
DirectXMatrix DirectXFromBytes(std::span<const std::uint8_t, 64> bytes);
/// The 64 little-endian bytes of `matrix`.
std::array<std::uint8_t, 64> BytesFromDirectX(const DirectXMatrix& matrix);

/// `b_from_a` [mm] from the hl2ss matrix M mapping a to b as p_b = [p_a 1] * M, translation in
/// elements 12..14 in metres (docs/ahat.md section 9.1): the column-vector form is M^T. IoError
/// naming `source` and `offset` (where the matrix starts) when M is not rigid.
Rigid3d RigidFromDirectX(const DirectXMatrix& matrix, const std::filesystem::path& source,
                         std::uint64_t offset);
/// The hl2ss matrix of `b_from_a`: rotation transposed, translation in metres in elements 12..14.
DirectXMatrix DirectXFromRigid(const Rigid3d& b_from_a);

}  // namespace tofnav
