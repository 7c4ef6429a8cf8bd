// SPDX-License-Identifier: BSD-3-Clause
// The NRRD header fields that matter for a scalar volume (internal to io/, used by nrrd.cpp).
#pragma once

#include <Eigen/Core>
#include <bit>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "tofnav/volume/volume_samples.hpp"

namespace tofnav {

struct NrrdHeader {
  SampleType type = SampleType::kUint8;
  int dimension = 0;
  std::vector<std::uint64_t> sizes;  ///< fastest axis first, each 1 .. 2^31-1
  /// Diagonal taking the header's space to LPS; nullopt when neither `space` nor
  /// `space dimension` is given.
  std::optional<Eigen::Vector3d> to_lps;
  std::string space_name;
  /// One entry per axis when `space directions` is given; nullopt entries are `none`.
  std::optional<std::vector<std::optional<Eigen::Vector3d>>> directions;
  std::optional<Eigen::Vector3d> origin;
  std::vector<double> spacings;  ///< empty, or one per axis
  std::endian endian = std::endian::little;
  std::string encoding;        ///< "raw" or "gzip"
  std::string data_file;       ///< empty: attached data
  std::int64_t byte_skip = 0;  ///< -1: data is the end of the file (raw only)
  std::int64_t line_skip = 0;
  std::uint64_t end_offset = 0;  ///< first byte after the header and its blank line
  bool blank_line = false;       ///< the header ended with a blank line (attached data follows)
};

/// Parses and cross-checks the header (magic, required fields, counts). IoError at the offending
/// line's offset on anything malformed or unsupported.
NrrdHeader ParseNrrdHeader(std::span<const std::uint8_t> bytes, const std::filesystem::path& path);

}  // namespace tofnav
