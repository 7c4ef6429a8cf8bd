// SPDX-License-Identifier: BSD-3-Clause
// Test-only helpers shared by the simulate test files.
#pragma once

#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <vector>

#include "tofnav/io/file.hpp"
#include "tofnav/sim/scenario.hpp"
#include "tofnav/sim/simulator.hpp"

namespace tofnav::testing {

using Json = nlohmann::json;

/// The default scenario camera, built once per test binary (slow to build unoptimised).
inline std::shared_ptr<const sim::SimulatorCamera> SharedCamera() {
  static const auto camera =
      std::make_shared<const sim::SimulatorCamera>(sim::CameraSetup().calibration);
  return camera;
}

inline Json ReadJson(const std::filesystem::path& path) {
  const std::vector<std::uint8_t> bytes = ReadFileBytes(path);
  return Json::parse(bytes.begin(), bytes.end());
}

}  // namespace tofnav::testing
