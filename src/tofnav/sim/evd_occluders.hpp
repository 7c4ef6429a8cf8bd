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
/// The hand hovers with its palm 35 mm over reference_right's plate, higher where the plate's
/// markers would reach into it.
void AddEvdOccluders(Scenario& scenario, const PatientHead& head, int headframe, int retro);

/// After reference_right's markers changed (tape to spheres on posts, ApplyVariation): lifts the
/// hand's pass over it, along the plate's normal, until no marker reaches into the hand or its
/// forearm. Nothing when the scenario has no hand or the pass already clears them.
void ClearEvdHandOverTools(Scenario& scenario);

}  // namespace tofnav::sim
