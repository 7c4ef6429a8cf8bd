// SPDX-License-Identifier: BSD-3-Clause
// The operating room of the built-in evd-usecase: a drape around the head, a hand passing over
// the forehead and over the right reference tool, an instrument passing over the left one.
#pragma once

#include <cstdint>

#include "tofnav/sim/patient.hpp"
#include "tofnav/sim/scenario.hpp"

namespace tofnav::sim {

/// Slots of the passes (docs/simulator.md section 7): each enters at its first slot, moves in for
/// kEvdMoveSlots, hovers, moves out for kEvdMoveSlots and is parked out of view again.
inline constexpr std::int64_t kEvdHandForeheadSlot = 400;
inline constexpr std::int64_t kEvdInstrumentSlot = 540;
inline constexpr std::int64_t kEvdHandReferenceSlot = 450;

/// Adds drape "drape" (on `headframe`), hand "hand" and instrument "instrument" (a spheres-four
/// array on a rod, tools/instrument.json) around `head`, whose mount `headframe` is `image`
/// moved to the anatomy centre. Needs the tools "reference_left" and "reference_right" on it.
/// The hand hovers with its palm's axis 35 mm over reference_right's plate (tape markers clear it
/// by 12.5 mm).
void AddEvdOccluders(Scenario& scenario, const PatientHead& head, int headframe, int retro);

/// After the reference tools' markers or the patient's motion changed (spheres on posts, drift;
/// ApplyVariation): lifts the hand's pass over reference_right and the instrument's over
/// reference_left, along the plate's normal, until no marker reaches into the hand or the
/// instrument at any of the pass's keyframes (the check simulate makes). Nothing where a pass
/// clears them already or the scenario has no such occluder.
void ClearEvdHandOverTools(Scenario& scenario);

}  // namespace tofnav::sim
