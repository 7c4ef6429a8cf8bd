// SPDX-License-Identifier: BSD-3-Clause
// Seed derivation for the simulator: independent, reproducible streams from one scenario seed.
#pragma once

#include <cstdint>

namespace tofnav::sim {

/// SplitMix64 finaliser (Steele et al. 2014).
constexpr std::uint64_t MixBits(std::uint64_t z) {
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

/// The seed of stream `stream` of `seed`: different streams are statistically independent.
constexpr std::uint64_t StreamSeed(std::uint64_t seed, std::uint64_t stream) {
  return MixBits(MixBits(seed + 0x9E3779B97F4A7C15ull) ^ (stream * 0xD1B54A32D192ED03ull + 1));
}

/// Streams of a simulation (fixed numbers: changing one changes every output of that kind).
enum class SeedStream : std::uint64_t {
  kRender = 1,
  kSlamJitter = 2,
  kFrameDrops = 3,
  kCtNoise = 4,
  kMounts = 100,  // + mount index; the camera uses kCamera
  kCamera = 99,
};

constexpr std::uint64_t StreamSeed(std::uint64_t seed, SeedStream stream, std::uint64_t index = 0) {
  return StreamSeed(seed, static_cast<std::uint64_t>(stream) + index);
}

}  // namespace tofnav::sim
