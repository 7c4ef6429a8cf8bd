// SPDX-License-Identifier: BSD-3-Clause
// Scenes of the published measurements that `tofnav evaluate fidelity` re-does on the simulator
// (issue 38 item 2; docs/simulator.md 10): the skin study's participants, Table I's phantom
// facing the headset and STTAR's static sphere tool.
#pragma once

#include <cstdint>
#include <vector>

#include "tofnav/sim/material.hpp"
#include "tofnav/sim/patient.hpp"
#include "tofnav/sim/scenario.hpp"

namespace tofnav::sim {

/// The spread of human skin in the simulator (docs/simulator.md 10, the row that fixes each):
/// the subsurface delay, normal about the skin preset's, so that the participants' mean bias
/// spreads as the skin study's (7.58 +- 1.49 mm over 10 participants), and the albedo drawn
/// uniformly from the darkest to the lightest skin at 850 nm.
struct SkinSpread {
  double delay_sd_ps = 11.0;  // 1.49 mm of bias: 0.9 x 7.49 mm per 50 ps x 11 ps
  double min_albedo = 0.15;
  double max_albedo = 0.6;
};

/// Participant `index` of a study drawn from `seed`: SkinMaterial() with its delay and albedo
/// drawn from `spread` (the same participant for the same seed and index).
Material SkinParticipant(std::uint64_t seed, int index, const SkinSpread& spread = {});

/// The skin study (paper Sec. III-A, 10 participants): `head` upright with `skin`, the
/// head-identification scene's four 10 mm forehead stickers, a headset worn 180-500 mm away;
/// `frames` frames.
Scenario SkinStudyScenario(const PatientHead& head, const Material& skin, std::int64_t frames);

/// Table I's "before" protocol: `head` made of `material`, static, a fixed headset
/// `distance_mm` in front of its forehead looking at it square on; `frames` frames, no drops.
Scenario FacingPhantomScenario(const PatientHead& head, const Material& material,
                               double distance_mm, std::int64_t frames);

/// STTAR's marker protocol (Martin-Gomez, Li et al., IEEE TVCG 2023; docs/simulator.md 10.1):
/// a fixed headset, a four-sphere tool held static at `positions` poses, each for
/// `frames_per_hold` frames and then moved `move_mm` along the camera's +z (away from it) and
/// held as long again. The markers' centroid of position p lies at depth (camera z)
/// min_depth_mm + p / (positions - 1) x (max_depth_mm - move_mm - min_depth_mm), so that both
/// holds of every position lie within [min_depth_mm, max_depth_mm]; its lateral offset (x and y,
/// each up to max_lateral_fraction x depth), tilt away from facing the camera (up to
/// max_tilt_rad, about a random in-plane axis) and spin about the tool normal are drawn from
/// `seed`.
struct MarkerNoiseProtocol {
  int positions = 12;
  std::int64_t frames_per_hold = 18;
  double min_depth_mm = 350.0;  // STTAR's 350-700 mm
  double max_depth_mm = 700.0;
  double move_mm = 20.0;  // STTAR's move along the camera's z
  double max_lateral_fraction = 0.2;
  double max_tilt_rad = 0.5236;  // 30 deg
  std::uint64_t seed = 1;
  void Check() const;  // throws PreconditionError naming the bad field
};

/// The tool of MarkerNoiseScenario (the "spheres-four" preset: 11.5 mm spheres, retro-reflective).
inline constexpr const char* kMarkerNoiseToolName = "sphere_tool";

/// One hold of MarkerNoiseScenario: frame slots [first_slot, first_slot + frames), tool static.
struct MarkerNoiseHold {
  int position = 0;
  bool moved = false;  // the second hold of a position: +move_mm along the camera's z
  std::int64_t first_slot = 0;
  std::int64_t frames = 0;
  Rigid3d ahat_from_tool;
};

/// The holds in slot order: position 0 static, position 0 moved, position 1 static, ...
std::vector<MarkerNoiseHold> MarkerNoiseHolds(const MarkerNoiseProtocol& protocol);

/// The protocol's scene: the headset fixed, the tool on a mount that steps through
/// MarkerNoiseHolds (no frame drops, so frame i is slot i).
Scenario MarkerNoiseScenario(const MarkerNoiseProtocol& protocol);

}  // namespace tofnav::sim
