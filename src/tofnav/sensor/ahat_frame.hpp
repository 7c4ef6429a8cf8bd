// SPDX-License-Identifier: BSD-3-Clause
// One AHAT frame as every reader returns it, whatever the file format.
#pragma once

#include <cstdint>
#include <optional>

#include "tofnav/core/image.hpp"
#include "tofnav/core/rigid3d.hpp"

namespace tofnav {

constexpr int kAhatWidth = 512;
constexpr int kAhatHeight = 512;
constexpr int kAhatPixels = kAhatWidth * kAhatHeight;
/// Raw AHAT range codes at or above this are invalid (4093 low signal, 4095 outside the
/// illumination); every reader maps them to 0.
constexpr std::uint16_t kAhatInvalidRange = 4090;
/// Phase-wrap distance of the single AHAT modulation frequency [mm].
constexpr double kAhatAliasMm = 1055.0;
/// Host ticks (QPC) are 100 ns.
constexpr double kSecondsPerHostTick = 1e-7;

/// Range, AB and pose of one AHAT frame. Range is radial along the pixel ray [mm], 0 = invalid.
struct AhatFrame {
  std::uint64_t host_ticks = 0;  // 100 ns since boot (hl2ss) or FILETIME (StreamRecorder)
  std::optional<std::uint64_t> sensor_ticks_ns;  // device clock, when the payload carries it
  Image<std::uint16_t> range_mm;                 // 512 x 512, 0 = invalid
  Image<std::uint16_t> ab;                       // 512 x 512 active brightness, counts
  double depth_step_mm = 1.0;                    // quantisation of range_mm (1, 2 or 4)
  bool ab_lossy = false;                         // AB went through a lossy video codec
  bool ab_half_res = false;                      // AB columns duplicated in pairs (SAME + H26x)
  std::optional<Rigid3d> world_from_rig;         // [mm]; nullopt when absent or the locator failed

  double timestamp_s() const { return static_cast<double>(host_ticks) * kSecondsPerHostTick; }
};

}  // namespace tofnav
