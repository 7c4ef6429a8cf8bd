// SPDX-License-Identifier: BSD-3-Clause
// "verify-landmarks": the accuracy check before guidance. evd-usecase's patient, headframe and
// wearer; its instrument, a pointer, rests on four skin landmarks in turn (docs/simulator.md).
#pragma once

#include "tofnav/sim/patient.hpp"
#include "tofnav/sim/scenario.hpp"

namespace tofnav::sim {

/// The landmarks a user touches: nasion, right and left lateral canthus (about where the rays
/// from the anatomy centre at +-0.6 rad leave the skin at eye level) and the forehead midline.
/// Points on `head`'s skin in image coordinates; touch slots unset.
std::vector<PlannedLandmark> VerifyLandmarks(const PatientHead& head);

/// `evd` (BuiltinScenario("evd-usecase") on `head`) turned into the check: the hand stays out of
/// view; the instrument ("instrument", a pointer with its tip in tools/instrument.json) comes in,
/// rests 1.6 s on each landmark with its rod leaning away from the skin towards the wearer, and
/// moves on to the next. The patient's landmarks get their touch slots; frames cover the whole.
Scenario VerifyLandmarksScenario(Scenario evd, const PatientHead& head);

}  // namespace tofnav::sim
