// SPDX-License-Identifier: BSD-3-Clause
// DICOM image series (one file per slice) through GDCM, into a CtVolume in LPS: slices sorted by
// position along the normal, spacing from positions, per-slice rescale (docs/openigtlink.md 5.2).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "tofnav/imaging/ct_volume.hpp"

namespace tofnav {

struct DicomSeriesOptions {
  /// The series to read; empty means the folder must hold exactly one image series.
  std::string series_instance_uid;
  /// Largest distance of a slice's ImagePositionPatient from the evenly spaced stack through the
  /// first and last slice, as a fraction of the mean slice spacing (dimensionless). Slicer only
  /// warns above 0.01 mm; we accept float noise and refuse real gaps or missing slices.
  double max_slice_deviation = 0.01;
  void Check() const;  ///< throws PreconditionError naming the bad field
};

/// One image series found in a folder.
struct DicomSeriesSummary {
  std::string series_instance_uid;
  std::string modality;
  std::string description;
  int file_count = 0;
};

/// The image series of the DICOM files directly in `folder` (non-DICOM files are skipped).
std::vector<DicomSeriesSummary> ListDicomSeries(const std::filesystem::path& folder);

/// Reads one series from the files directly in `folder`. IoError when the folder holds no series,
/// several series (the message lists their UIDs) and none was chosen, a single slice, slices of
/// different size, orientation or pixel spacing, duplicate or unevenly spaced positions,
/// multi-frame or colour images, or pixel data GDCM cannot decode.
CtVolume ReadDicomSeries(const std::filesystem::path& folder,
                         const DicomSeriesOptions& options = {});

}  // namespace tofnav
