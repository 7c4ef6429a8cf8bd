// SPDX-License-Identifier: BSD-3-Clause
// Marker layouts of the tools used in the paper's experiments, as simulator tools.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "tofnav/sim/scene.hpp"

namespace tofnav::sim {

/// "planar-six": six 10 mm tape discs on a 90 x 70 mm plate (the reconstruction tool);
/// "tape-seven": the IR-tape test structure, a 20 mm centre circle and six 12 mm circles on a
/// 140 x 140 mm plate; "reference-a", "reference-b": four 10 mm discs on 80 x 60 mm plates
/// (the two headframe tools); "spheres-four": four 11.5 mm spheres on 8 mm posts.
std::vector<std::string> ToolPresetNames();

/// A preset tool: its markers (material `material`) in a tool frame whose origin is the plate
/// centre and whose +z is the plate normal (discs face +z, lifted 0.1 mm above z = 0).
/// Throws PreconditionError for an unknown preset (the message lists the names).
Tool ToolPreset(const std::string& preset, std::string name, int material);

/// The preset's plate size [mm] (width along x, height along y), or zero for "spheres-four".
Eigen::Vector2d ToolPresetPlateMm(const std::string& preset);

}  // namespace tofnav::sim
