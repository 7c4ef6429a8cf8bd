// SPDX-License-Identifier: BSD-3-Clause
// Built-in scenarios: one per experiment of the paper (Sec. III-A, IV and V).
#pragma once

#include <string>
#include <vector>

#include "tofnav/sim/patient.hpp"
#include "tofnav/sim/scenario.hpp"

namespace tofnav::sim {

/// "marker-stage", "materials", "head-identification", "depth-accuracy", "reconstruction",
/// "reconstruction-shapes", "reconstruction-shapes-pp", "evd-usecase", "pivot-calibration",
/// "verify-landmarks" (docs/simulator.md).
std::vector<std::string> BuiltinScenarioNames();

/// One-line summary of a built-in.
std::string BuiltinScenarioSummary(const std::string& name);

/// The built-in scenario `name`; PreconditionError for an unknown name (the message lists them).
/// `head` replaces the built-in phantom in the scenarios with a patient (head-identification,
/// reconstruction, evd-usecase; PreconditionError for the others): its anatomy centre takes the
/// phantom's place.
Scenario BuiltinScenario(const std::string& name, const PatientHead* head = nullptr);

}  // namespace tofnav::sim
