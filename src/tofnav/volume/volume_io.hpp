// SPDX-License-Identifier: BSD-3-Clause
// One entry point for CT/MR volumes: DICOM folder, NRRD, NIfTI-1 or InVesalius .inv3 into a
// CtVolume in LPS (docs/openigtlink.md section 5); writers for .nrrd, .nii and .nii.gz.
#pragma once

#include <filesystem>

#include "tofnav/imaging/ct_volume.hpp"

namespace tofnav {

/// Sample type written to disk.
enum class VolumeSampleType {
  kFloat32,
  kInt16,  ///< values rounded to the nearest integer; must lie in [-32768, 32767]
};

struct VolumeWriteOptions {
  VolumeSampleType sample_type = VolumeSampleType::kFloat32;
  /// NRRD: gzip encoding (else raw). NIfTI ignores it: .nii.gz is gzip, .nii is not.
  bool gzip = true;
  /// zlib level 0..9: 1 writes a head CT 4x faster than 6 for 3 % more bytes (docs/benchmarks.md)
  int gzip_level = 1;
  void Check() const;  ///< throws PreconditionError naming the bad field
};

/// Reads a volume, choosing the reader by content (gzip/tar, NRRD magic, NIfTI sizeof_hdr) and
/// then by extension; a folder is read as a DICOM series (exactly one series). IoError on failure.
CtVolume ReadVolume(const std::filesystem::path& path);

/// Writes by extension: .nrrd, .nii or .nii.gz (IoError for any other). Checks the volume first
/// (PreconditionError), then writes atomically.
void WriteVolume(const std::filesystem::path& path, const CtVolume& volume,
                 const VolumeWriteOptions& options = {});

}  // namespace tofnav
