// SPDX-License-Identifier: BSD-3-Clause
// Per-pixel truth of a simulated frame by ray casting the scenario at truth.json's poses.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "tofnav/core/image.hpp"
#include "tofnav/core/rigid3d.hpp"
#include "tofnav/sensor/ahat_camera.hpp"
#include "tofnav/sim/raycaster.hpp"
#include "tofnav/sim/scenario.hpp"
#include "tofnav/sim/scene.hpp"

namespace tofnav {

/// A simulation's truth.json and the scenario that made it.
struct SimulationTruth {
  nlohmann::json truth;
  sim::Scenario scenario;
};

/// DIR/truth.json and its scenario: `scenario_name` (built-in or file) when not empty, else
/// truth.json's "scenario" with the patient head it was simulated with (`ct:`, `mesh:` or the
/// phantom). Throws IoError when truth.json cannot be read.
SimulationTruth ReadSimulationTruth(const std::filesystem::path& dir, std::string scenario_name);

/// A 4 x 4 matrix of truth.json (rows of numbers) as a rigid transform.
Rigid3d TruthMatrix(const nlohmann::json& rows);

/// What each pixel's centre ray hits first.
struct TruthHits {
  Image<int> object;      // index into Scene::objects; -1 none, -2 a marker
  Image<int> material;    // index into Scene::materials; -1 none
  Image<float> range_mm;  // true range along the unit ray; 0 = no hit
};

/// Poses the scene's objects and tools from one frame of truth.json ("ahat_from_objects",
/// "ahat_from_<tool>", 4 x 4 matrices in mm) and casts every valid pixel's ray.
TruthHits CastTruthHits(sim::Scene& scene, sim::SceneRaycaster& caster,
                        const nlohmann::json& truth_frame, const AhatCamera& camera);

}  // namespace tofnav
