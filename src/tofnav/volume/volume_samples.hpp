// SPDX-License-Identifier: BSD-3-Clause
// Typed voxel samples shared by the NRRD and NIfTI readers/writers (internal to io/).
#pragma once

#include <array>
#include <bit>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <vector>

#include "tofnav/volume/volume_io.hpp"

namespace tofnav {

enum class SampleType {
  kInt8,
  kUint8,
  kInt16,
  kUint16,
  kInt32,
  kUint32,
  kInt64,
  kUint64,
  kFloat32,
  kFloat64
};

/// double -> float without undefined behaviour: beyond the float range gives +-infinity.
float NarrowToFloat(double value);

/// Bytes per sample.
std::size_t SampleSize(SampleType type);

/// Converts values.size() samples from `bytes` (exactly values.size() * SampleSize bytes) to float.
void DecodeSamples(std::span<const std::uint8_t> bytes, SampleType type, std::endian endian,
                   std::span<float> values);

/// Little-endian float32 or int16 samples of `values` (int16: rounded; PreconditionError when a
/// value is not finite or out of range).
std::vector<std::uint8_t> EncodeSamples(std::span<const float> values, VolumeSampleType type);

/// nx * ny * nz * sample_size when every factor is positive and the product fits in 63 bits;
/// nullopt otherwise (callers raise IoError with their own offset).
std::optional<std::uint64_t> CheckedVolumeBytes(std::span<const std::uint64_t> sizes,
                                                std::size_t sample_size);

}  // namespace tofnav
