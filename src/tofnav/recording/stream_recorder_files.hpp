// SPDX-License-Identifier: BSD-3-Clause
// StreamRecorder side files: unit-ray LUT and transposed text matrices (docs/ahat.md 7.4-7.5).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <map>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "tofnav/core/image.hpp"
#include "tofnav/core/rigid3d.hpp"

namespace tofnav {

/// Size of `Depth AHaT_lut.bin` [bytes]: 512 x 512 x 3 float32.
inline constexpr std::uint64_t kStreamRecorderLutBytes = 512 * 512 * 3 * 4;

/// `Depth AHaT_lut.bin`: 512 x 512 x 3 little-endian f32 unit rays sampled at (u + 0.5, v + 0.5),
/// raster order, to the unit-plane table (x / z, y / z); NaN where z <= 0 (the recorder writes
/// z = 0 when the API call failed) or a value is not finite. IoError unless exactly 3 145 728 B.
Image<Eigen::Vector2f> DecodeStreamRecorderLut(std::span<const std::uint8_t> bytes,
                                               const std::filesystem::path& source);
/// Inverse: (x, y, 1) / |(x, y, 1)|, and (0, 0, 0) where the table holds NaN.
/// PreconditionError unless `uv2xy` is 512 x 512.
std::vector<std::uint8_t> EncodeStreamRecorderLut(const Image<Eigen::Vector2f>& uv2xy);

/// `Depth AHaT_extrinsics.txt`: one line of 16 comma-separated numbers, the column-vector
/// rig -> camera matrix in metres (the recorder's transposed DirectX matrix), as rig_from_ahat
/// [mm]. IoError naming `source` and the byte offset of the bad line.
Rigid3d ParseStreamRecorderExtrinsics(std::string_view text, const std::filesystem::path& source);
/// The inverse of the parse, 9 significant digits, one "\n"-terminated line.
std::string FormatStreamRecorderExtrinsics(const Rigid3d& rig_from_ahat);

/// `Depth AHaT_rig2world.txt`: lines `ts,` + 16 numbers (column-vector rig -> world, metres) to
/// world_from_rig [mm] by FILETIME. Blank lines and CRLF are accepted; a duplicate timestamp or
/// a malformed line is an IoError at that line's byte offset.
std::map<std::uint64_t, Rigid3d> ParseStreamRecorderRig2World(std::string_view text,
                                                              const std::filesystem::path& source);
/// One "\n"-terminated rig2world line, 9 significant digits.
std::string FormatStreamRecorderRig2WorldLine(std::uint64_t filetime,
                                              const Rigid3d& world_from_rig);

}  // namespace tofnav
