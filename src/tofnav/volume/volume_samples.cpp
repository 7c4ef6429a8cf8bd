// SPDX-License-Identifier: BSD-3-Clause
// Typed sample decoding (any endianness) to float and float32/int16 encoding.
#include "tofnav/volume/volume_samples.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "tofnav/core/require.hpp"

namespace tofnav {
namespace {

template <typename T>
void DecodeTyped(std::span<const std::uint8_t> bytes, bool swap, std::span<float> values) {
  std::array<std::uint8_t, sizeof(T)> raw{};
  for (std::size_t n = 0; n < values.size(); ++n) {
    std::memcpy(raw.data(), bytes.data() + n * sizeof(T), sizeof(T));
    if (swap) std::reverse(raw.begin(), raw.end());
    T sample;
    std::memcpy(&sample, raw.data(), sizeof(T));
    values[n] = NarrowToFloat(static_cast<double>(sample));
  }
}

}  // namespace

float NarrowToFloat(double value) {
  constexpr double kMax = std::numeric_limits<float>::max();
  if (value > kMax) return std::numeric_limits<float>::infinity();
  if (value < -kMax) return -std::numeric_limits<float>::infinity();
  return static_cast<float>(value);
}

std::size_t SampleSize(SampleType type) {
  switch (type) {
    case SampleType::kInt8:
    case SampleType::kUint8:
      return 1;
    case SampleType::kInt16:
    case SampleType::kUint16:
      return 2;
    case SampleType::kInt32:
    case SampleType::kUint32:
    case SampleType::kFloat32:
      return 4;
    case SampleType::kInt64:
    case SampleType::kUint64:
    case SampleType::kFloat64:
      return 8;
  }
  return 1;
}

void DecodeSamples(std::span<const std::uint8_t> bytes, SampleType type, std::endian endian,
                   std::span<float> values) {
  Require(bytes.size() == values.size() * SampleSize(type), "sample bytes must match the count");
  const bool swap = endian != std::endian::native;
  switch (type) {
    case SampleType::kInt8:
      return DecodeTyped<std::int8_t>(bytes, swap, values);
    case SampleType::kUint8:
      return DecodeTyped<std::uint8_t>(bytes, swap, values);
    case SampleType::kInt16:
      return DecodeTyped<std::int16_t>(bytes, swap, values);
    case SampleType::kUint16:
      return DecodeTyped<std::uint16_t>(bytes, swap, values);
    case SampleType::kInt32:
      return DecodeTyped<std::int32_t>(bytes, swap, values);
    case SampleType::kUint32:
      return DecodeTyped<std::uint32_t>(bytes, swap, values);
    case SampleType::kInt64:
      return DecodeTyped<std::int64_t>(bytes, swap, values);
    case SampleType::kUint64:
      return DecodeTyped<std::uint64_t>(bytes, swap, values);
    case SampleType::kFloat32:
      return DecodeTyped<float>(bytes, swap, values);
    case SampleType::kFloat64:
      return DecodeTyped<double>(bytes, swap, values);
  }
}

std::vector<std::uint8_t> EncodeSamples(std::span<const float> values, VolumeSampleType type) {
  const bool swap = std::endian::native != std::endian::little;
  std::vector<std::uint8_t> bytes;
  if (type == VolumeSampleType::kFloat32) {
    bytes.resize(values.size() * sizeof(float));
    for (std::size_t n = 0; n < values.size(); ++n) {
      std::memcpy(bytes.data() + n * sizeof(float), &values[n], sizeof(float));
      if (swap)
        std::reverse(bytes.begin() + static_cast<std::ptrdiff_t>(n * sizeof(float)),
                     bytes.begin() + static_cast<std::ptrdiff_t>((n + 1) * sizeof(float)));
    }
    return bytes;
  }
  bytes.resize(values.size() * sizeof(std::int16_t));
  for (std::size_t n = 0; n < values.size(); ++n) {
    const float rounded = std::nearbyint(values[n]);
    Require(std::isfinite(rounded) && rounded >= std::numeric_limits<std::int16_t>::min() &&
                rounded <= std::numeric_limits<std::int16_t>::max(),
            "int16 output needs finite values in [-32768, 32767]");
    const auto sample = static_cast<std::int16_t>(rounded);
    const auto bits = static_cast<std::uint16_t>(sample);
    bytes[2 * n] = static_cast<std::uint8_t>(bits & 0xffu);
    bytes[2 * n + 1] = static_cast<std::uint8_t>(bits >> 8);
  }
  return bytes;
}

std::optional<std::uint64_t> CheckedVolumeBytes(std::span<const std::uint64_t> sizes,
                                                std::size_t sample_size) {
  constexpr std::uint64_t kLimit = std::uint64_t{1} << 62;
  std::uint64_t total = sample_size;
  for (const std::uint64_t size : sizes) {
    if (size == 0 || size > kLimit / total) return std::nullopt;
    total *= size;
  }
  return total;
}

}  // namespace tofnav
