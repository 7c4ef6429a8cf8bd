// SPDX-License-Identifier: BSD-3-Clause
// Built-in scenarios: one per experiment of the paper (Sec. III-A, IV and V).
#pragma once

#include <string>
#include <vector>

#include "tofnav/sim/scenario.hpp"

namespace tofnav::sim {

/// "marker-stage", "materials", "head-identification", "depth-accuracy", "reconstruction",
/// "reconstruction-shapes", "reconstruction-shapes-pp", "evd-usecase" (docs/simulator.md).
std::vector<std::string> BuiltinScenarioNames();

/// One-line summary of a built-in.
std::string BuiltinScenarioSummary(const std::string& name);

/// The built-in scenario `name`; PreconditionError for an unknown name (the message lists them).
Scenario BuiltinScenario(const std::string& name);

}  // namespace tofnav::sim
