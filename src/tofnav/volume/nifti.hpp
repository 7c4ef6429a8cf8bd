// SPDX-License-Identifier: BSD-3-Clause
// NIfTI-1 single-file volumes (.nii, .nii.gz) per nifti1.h: sform, else qform, else pixdim
// (docs/openigtlink.md 5.2), RAS converted to LPS; scl_slope/scl_inter applied.
#pragma once

#include <cstdint>
#include <filesystem>
#include <span>
#include <vector>

#include "tofnav/imaging/ct_volume.hpp"
#include "tofnav/volume/volume_io.hpp"

namespace tofnav {

/// Decodes a whole .nii file, or a .nii.gz (detected by its gzip magic), held in memory.
/// geometry_source says which rule was used: "nifti sform (code N)", "nifti qform (code N)" or
/// "nifti pixdim (no sform/qform)". IoError naming `path` and the offset on malformed input
/// (offsets inside a .nii.gz count decompressed bytes and say so).
CtVolume DecodeNifti(std::span<const std::uint8_t> bytes, const std::filesystem::path& path);
CtVolume ReadNifti(const std::filesystem::path& path);

/// An uncompressed .nii image: 348-byte header + 4 zero extension bytes, vox_offset 352, float32
/// or int16 samples, little-endian, mm units, sform_code = qform_code = 1 (scanner). The qform
/// holds the nearest rotation when image_from_ijk has shear; the sform is exact (float32).
std::vector<std::uint8_t> EncodeNifti(const CtVolume& volume,
                                      const VolumeWriteOptions& options = {});
/// Writes .nii, or gzip-compressed when the name ends in .gz.
void WriteNifti(const std::filesystem::path& path, const CtVolume& volume,
                const VolumeWriteOptions& options = {});

}  // namespace tofnav
