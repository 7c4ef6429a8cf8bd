// SPDX-License-Identifier: BSD-3-Clause
// NRRD (teem.sourceforge.net/nrrd/format.html, NRRD0001..0005) volumes: raw or gzip, attached or
// detached data, any space directions; RAS/LAS spaces are converted to LPS.
#pragma once

#include <cstdint>
#include <filesystem>
#include <span>
#include <vector>

#include "tofnav/imaging/ct_volume.hpp"
#include "tofnav/volume/volume_io.hpp"

namespace tofnav {

struct NrrdDecodeOptions {
  /// Folder against which a relative `data file:` is resolved; empty forbids detached data
  /// (decoding untrusted bytes in memory).
  std::filesystem::path data_folder;
};

/// Decodes a NRRD header and its data. `path` names the source in IoError messages. Accepts
/// dimension 3, or 4 with a leading non-spatial axis of size 1 (ITK/Slicer's layout).
CtVolume DecodeNrrd(std::span<const std::uint8_t> bytes, const std::filesystem::path& path,
                    const NrrdDecodeOptions& options = {});

/// Reads a .nrrd (attached) or .nhdr (detached data next to it) file.
CtVolume ReadNrrd(const std::filesystem::path& path);

/// NRRD0004 with `space: left-posterior-superior`, space directions/origin from image_from_ijk,
/// little-endian float or short, gzip or raw (options). PreconditionError on an invalid volume.
std::vector<std::uint8_t> EncodeNrrd(const CtVolume& volume,
                                     const VolumeWriteOptions& options = {});
void WriteNrrd(const std::filesystem::path& path, const CtVolume& volume,
               const VolumeWriteOptions& options = {});

}  // namespace tofnav
