// SPDX-License-Identifier: BSD-3-Clause
// hl2ss AHAT calibration: the `rm_depth_ahat/` folder and the Mode-2 blob (docs/ahat.md section 5).
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <vector>

#include "tofnav/sensor/ahat_calibration.hpp"

namespace tofnav {

/// Bytes of the Mode-2 blob: (4 * 512 * 512 + 22) f32.
constexpr std::size_t kHl2ssMode2Bytes = 4'194'392;

/// Reads `<path>/rm_depth_ahat/` or, when `path` is that folder, `<path>/`: uv2xy.bin,
/// extrinsics.bin, intrinsics.bin, undistort_map.bin, scale.bin, alias.bin (exact sizes).
/// The files do not record the table's sample offset s: `sample_offset_override` (0 or 0.5)
/// wins, else the auto rule of docs/ahat.md 5.3 applies (fx == fy -> 0, otherwise 0.5).
AhatCalibration ReadHl2ssCalibration(const std::filesystem::path& path,
                                     std::optional<double> sample_offset_override = std::nullopt);

/// Writes `<folder>/rm_depth_ahat/` (each file atomically). An empty undistort map is written as
/// -1 everywhere. s is not stored: readers recover it only when fx == fy <=> s == 0.
void WriteHl2ssCalibration(const std::filesystem::path& folder, const AhatCalibration& calibration);

/// Decodes the planar Mode-2 blob of a live server; `source` names it in errors.
AhatCalibration DecodeHl2ssMode2(std::span<const std::uint8_t> bytes,
                                 const std::filesystem::path& source = "<hl2ss mode 2>",
                                 std::optional<double> sample_offset_override = std::nullopt);
/// The Mode-2 blob of `calibration`.
std::vector<std::uint8_t> EncodeHl2ssMode2(const AhatCalibration& calibration);

// Through AhatCalibration the tables, K, scale and alias are kept bit for bit, but the f32
// extrinsics pass through a Rigid3d (double, re-orthonormalised) and come back within f32
// rounding only. The two conversions below rearrange the stored floats without decoding them,
// so they are bitwise lossless (the replay server sends the device's own bytes).

/// The Mode-2 blob of a calibration folder (as ReadHl2ssCalibration finds it), byte exact.
std::vector<std::uint8_t> ReadHl2ssCalibrationAsMode2(const std::filesystem::path& path);
/// Writes `<folder>/rm_depth_ahat/` from a Mode-2 blob, byte exact.
void WriteHl2ssMode2AsFolder(const std::filesystem::path& folder,
                             std::span<const std::uint8_t> bytes,
                             const std::filesystem::path& source = "<hl2ss mode 2>");

}  // namespace tofnav
