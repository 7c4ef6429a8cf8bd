// SPDX-License-Identifier: BSD-3-Clause
// The axes along which the robustness suite varies a patient session (docs/simulator.md,
// "Scenario variations"): tools, occluders, surroundings, patient motion, frame drops, SLAM
// jitter and the headset's own calibration.
#pragma once

#include <cstdint>
#include <string>

#include "tofnav/sensor/ahat_calibration.hpp"
#include "tofnav/sim/scenario.hpp"

namespace tofnav::sim {

/// How the headframe's reference tools are built.
enum class ReferenceTools {
  kAsBuilt,     // as the scenario has them (evd-usecase: two plates of 10 mm tape discs)
  kSpheres,     // the same layouts as 11.5 mm spheres on 8 mm posts above the plates
  kSingleTool,  // only the first reference tool (the second one and its plate removed)
};

/// What lies around the head besides the headframe's board.
enum class Surroundings {
  kAsBuilt,
  kPillow,  // a bright fabric pillow (an ellipsoid) against the back of the head
  kBare,    // every object named "drape*" or "pillow*" removed
};

/// One variation of a patient session. Defaults change nothing.
struct ScenarioVariation {
  ReferenceTools tools = ReferenceTools::kAsBuilt;
  Surroundings surroundings = Surroundings::kAsBuilt;
  bool occluders = true;  // false: objects and tools named "hand*" / "instrument*" removed
  /// Slow patient motion: the headframe (and everything on it) drifts at this speed along a
  /// fixed oblique direction, up to `head_drift_mm` [mm/s]; 0 keeps it still.
  double head_drift_mm_per_s = 0.0;
  double head_drift_mm = 20.0;
  double drop_probability = -1.0;           // >= 0 replaces the scenario's timing value
  double mean_drop_slots = -1.0;            // >= 1 replaces it
  double no_hand_rate_hz = -1.0;            // >= 0 replaces the rate without a hand in view
  double slam_translation_sigma_mm = -1.0;  // >= 0 replaces the headset pose jitter
  double slam_rotation_sigma_rad = -1.0;    // >= 0 replaces it
  /// The patients users have (issue 38 item 4): >= 0 makes the head skin (SkinMaterial, its
  /// subsurface delay) of this surface albedo, from the darkest of the skin study's calibrated
  /// spread (0.15) to the lightest (0.6, docs/simulator.md 10); < 0 keeps the scenario's
  /// material (evd-usecase: a nylon print of the head).
  double skin_albedo = -1.0;
  /// >= 0 replaces the wearer's closest / farthest range to the head [mm] (evd-usecase: 300-700).
  double headset_min_range_mm = -1.0;
  double headset_max_range_mm = -1.0;
  void Check() const;  // throws PreconditionError naming the bad field
};

/// Applies `variation` to a session with a patient on a mount (evd-usecase and the like).
/// PreconditionError when the scenario lacks what the variation changes (no reference tool).
void ApplyVariation(const ScenarioVariation& variation, Scenario& scenario);

/// Spread of real HoloLens 2 units around the synthetic model (docs/simulator.md): focal length
/// +-2 %, principal point +-4 px, extrinsics +-2 mm and +-1 deg per axis.
struct DeviceSpread {
  double focal_fraction = 0.02;
  double principal_point_px = 4.0;
  double translation_mm = 2.0;
  double rotation_rad = 0.017453292519943295;
};

/// Another plausible device: `base` with each quantity drawn uniformly within the spread from
/// `seed` (the same seed, the same device).
SyntheticAhatOptions PerturbedDevice(const SyntheticAhatOptions& base, std::uint64_t seed,
                                     const DeviceSpread& spread = {});

}  // namespace tofnav::sim
