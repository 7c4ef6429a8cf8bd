// SPDX-License-Identifier: BSD-3-Clause
// Frame slots, drops and SLAM jitter.
#include "tofnav/sim/timing.hpp"

#include <Eigen/Geometry>
#include <cmath>

#include "tofnav/core/require.hpp"
#include "tofnav/core/rotation_vector.hpp"

namespace tofnav::sim {
namespace {

constexpr double kTicksPerSecond = 1e7;  // hl2ss host ticks are 100 ns

double Uniform(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

}  // namespace

void FrameTimingOptions::Check() const {
  Require(std::isfinite(rate_hz) && rate_hz > 0.0 && rate_hz <= 1000.0,
          "FrameTimingOptions.rate_hz must lie in (0, 1000]");
  Require(drop_probability >= 0.0 && drop_probability < 1.0,
          "FrameTimingOptions.drop_probability must lie in [0, 1)");
  Require(std::isfinite(mean_drop_slots) && mean_drop_slots >= 1.0,
          "FrameTimingOptions.mean_drop_slots must be >= 1");
  Require(start_ticks < (std::uint64_t{1} << 62), "FrameTimingOptions.start_ticks is too large");
  Require(slot_stride >= 1 && slot_stride <= 1000,
          "FrameTimingOptions.slot_stride must lie in [1, 1000]");
  Require(std::isfinite(no_hand_rate_hz) && no_hand_rate_hz >= 0.0 && no_hand_rate_hz <= rate_hz,
          "FrameTimingOptions.no_hand_rate_hz must lie in [0, rate_hz]");
}

std::uint64_t SlotTicks(const FrameTimingOptions& options, std::int64_t slot) {
  Require(slot >= 0, "SlotTicks: slot must be >= 0");
  const double offset = std::round(static_cast<double>(slot) * kTicksPerSecond / options.rate_hz);
  return options.start_ticks + static_cast<std::uint64_t>(offset);
}

FrameClock::FrameClock(const FrameTimingOptions& options, std::uint64_t seed)
    : options_(options), rng_(seed) {
  options_.Check();
}

std::int64_t FrameClock::NextSlot(const std::function<bool(std::int64_t)>& hand_in_view) {
  std::int64_t slot = NextRandomSlot();
  if (options_.no_hand_rate_hz > 0.0 && hand_in_view && last_kept_ >= 0) {
    // Without a hand the camera delivers a frame every rate_hz / no_hand_rate_hz slots.
    const double period = options_.rate_hz / options_.no_hand_rate_hz;
    while (static_cast<double>(slot - last_kept_) < period - 1e-9 && !hand_in_view(slot)) {
      ++dropped_;  // this slot (NextRandomSlot counts the ones it passes over)
      ++throttled_;
      slot = NextRandomSlot();
    }
  }
  last_kept_ = slot;
  return slot;
}

std::int64_t FrameClock::NextRandomSlot() {
  const std::int64_t stride = options_.slot_stride;
  const std::int64_t slot = next_;
  next_ += stride;
  if (slot > 0) dropped_ += stride - 1;  // the thinned slots before this one
  if (slot == 0 || options_.drop_probability <= 0.0) return slot;
  // A run of drops starts after a kept slot with drop_probability and continues with
  // 1 - 1 / mean_drop_slots per further slot (geometric length).
  if (Uniform(rng_) >= options_.drop_probability) return slot;
  const double keep_dropping = 1.0 - 1.0 / options_.mean_drop_slots;
  std::int64_t skipped = 1;
  while (Uniform(rng_) < keep_dropping) ++skipped;
  dropped_ += skipped * stride;
  next_ += skipped * stride;
  return slot + skipped * stride;
}

void SlamJitterOptions::Check() const {
  Require(std::isfinite(translation_sigma_mm) && translation_sigma_mm >= 0.0,
          "SlamJitterOptions.translation_sigma_mm must be >= 0");
  Require(std::isfinite(rotation_sigma_rad) && rotation_sigma_rad >= 0.0,
          "SlamJitterOptions.rotation_sigma_rad must be >= 0");
}

Rigid3d JitterPose(const Rigid3d& world_from_rig, const SlamJitterOptions& options,
                   std::mt19937_64& rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  Eigen::Vector3d rotation_vector, translation;
  for (int i = 0; i < 3; ++i) rotation_vector[i] = options.rotation_sigma_rad * normal(rng);
  for (int i = 0; i < 3; ++i) translation[i] = options.translation_sigma_mm * normal(rng);
  return world_from_rig * Rigid3d(FromRotationVector(rotation_vector), translation);
}

}  // namespace tofnav::sim
