// SPDX-License-Identifier: BSD-3-Clause
// Simulation scenarios from JSON files (schema: docs/simulator.md) or built-in names.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

#include "tofnav/sim/scenario.hpp"

namespace tofnav {

/// Parses a scenario document. Missing keys keep their defaults; unknown keys, wrong types and
/// bad values are IoError naming `source` and the JSON path (e.g. "$.objects[2].shape.kind").
/// Relative mesh paths are resolved against source's folder.
sim::Scenario ParseScenarioJson(std::string_view text, const std::filesystem::path& source);

/// Reads and parses a scenario file.
sim::Scenario ReadScenarioFile(const std::filesystem::path& path);

/// A built-in scenario by name (sim::BuiltinScenarioNames) or else a scenario file; IoError when
/// it is neither.
sim::Scenario LoadScenario(const std::string& name_or_path);

}  // namespace tofnav
