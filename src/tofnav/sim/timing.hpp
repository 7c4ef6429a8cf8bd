// SPDX-License-Identifier: BSD-3-Clause
// Frame timing of the simulated AHAT stream (45 Hz host ticks, frame drops) and the SLAM jitter
// of the rig poses the headset reports.
#pragma once

#include <cstdint>
#include <functional>
#include <random>

#include "tofnav/core/rigid3d.hpp"

namespace tofnav::sim {

/// Frame slots are the nominal frame times; a dropped slot produces no frame.
struct FrameTimingOptions {
  double rate_hz = 45.0;
  /// Host ticks (100 ns, QPC since boot) of slot 0; default one hour after boot.
  std::uint64_t start_ticks = 36'000'000'000;
  double drop_probability = 0.0;  // chance that a kept slot is followed by a dropped one
  double mean_drop_slots = 1.0;   // mean length of a run of dropped slots (geometric, >= 1)
  /// Keep every n-th slot only (the others count as dropped): the same motion over its whole
  /// duration in 1/n of the frames, e.g. the short runs of the robustness suite (docs/suite.md).
  std::int64_t slot_stride = 1;
  /// > 0: the rate [Hz] of the real AHAT camera while no hand is in view (about 5 Hz on a
  /// HoloLens 2: its hand tracker throttles the camera, docs/simulator.md 6.8); 0: always rate_hz.
  double no_hand_rate_hz = 0.0;
  void Check() const;  // throws PreconditionError naming the bad field
};

/// Host ticks of slot `slot`: start_ticks + round(slot * 1e7 / rate_hz).
std::uint64_t SlotTicks(const FrameTimingOptions& options, std::int64_t slot);

/// Walks the slots and skips the dropped ones. Slot 0 is always kept.
class FrameClock {
 public:
  FrameClock(const FrameTimingOptions& options, std::uint64_t seed);
  /// The next kept slot (0 on the first call). With no_hand_rate_hz, `hand_in_view(slot)` says
  /// whether a hand is seen at a slot; while none is, slots closer than 1 / no_hand_rate_hz to
  /// the last kept one are skipped (counted as dropped).
  std::int64_t NextSlot(const std::function<bool(std::int64_t)>& hand_in_view = {});
  std::int64_t dropped_slots() const { return dropped_; }
  /// Slots skipped because no hand was in view.
  std::int64_t throttled_slots() const { return throttled_; }

 private:
  std::int64_t NextRandomSlot();

  FrameTimingOptions options_;
  std::mt19937_64 rng_;
  std::int64_t next_ = 0;
  std::int64_t dropped_ = 0;
  std::int64_t throttled_ = 0;
  std::int64_t last_kept_ = -1;
};

/// Error of the headset's reported rig pose (spatial tracking), white per frame.
struct SlamJitterOptions {
  double translation_sigma_mm = 0.3;  // per axis
  double rotation_sigma_rad = 3e-4;   // per axis of the rotation vector (about 0.02 deg)
  void Check() const;
};

/// The reported pose: world_from_rig * delta, delta a small random motion in the rig frame.
Rigid3d JitterPose(const Rigid3d& world_from_rig, const SlamJitterOptions& options,
                   std::mt19937_64& rng);

}  // namespace tofnav::sim
