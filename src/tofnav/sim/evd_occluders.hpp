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
void AddEvdOccluders(Scenario& scenario, const PatientHead& head, int headframe, int retro);

}  // namespace tofnav::sim
