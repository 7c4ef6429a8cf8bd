// SPDX-License-Identifier: BSD-3-Clause
// Scenes of the published measurements that `tofnav evaluate fidelity` re-does on the simulator
// (issue 38 item 2; docs/simulator.md 10): the skin study's participants and Table I's phantom
// facing the headset.
#pragma once

#include <cstdint>

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

}  // namespace tofnav::sim
