// SPDX-License-Identifier: BSD-3-Clause
// InVesalius 3 projects (.inv3): a gzip'd tar holding main.plist (Apple XML plist) and the CT as
// matrix.dat (int16 little-endian, shape (z, y, x)); see docs/openigtlink.md section 8.1.
#pragma once

#include <cstdint>
#include <filesystem>
#include <span>

#include "tofnav/imaging/ct_volume.hpp"

namespace tofnav {

/// Decodes the CT of an .inv3 held in memory. The project stores spacing (x, y, z) but no origin
/// or direction; we take origin 0 and image_from_ijk = diag(sx, -sy, sz): InVesalius keeps the
/// rows bottom-up (VTK order), so row index j runs posterior -> anterior. This puts the face
/// anterior and the vertex superior in LPS (checked on the Debian Cranium.inv3) and matches the
/// frame of the project's own surface_N.vtp meshes. Left/right cannot be told from the anatomy:
/// i -> patient left is assumed, as in a standard axial DICOM stack. Only axial projects
/// (`orientation` 1 or absent) with dtype int16 are accepted. IoError offsets count bytes of the
/// decompressed tar.
CtVolume DecodeInv3(std::span<const std::uint8_t> bytes, const std::filesystem::path& path);
CtVolume ReadInv3(const std::filesystem::path& path);

}  // namespace tofnav
