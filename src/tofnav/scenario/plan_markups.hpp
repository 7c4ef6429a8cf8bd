// SPDX-License-Identifier: BSD-3-Clause
// Planned trajectories as a 3D Slicer markups file (.mrk.json, docs/openigtlink.md section 5.4).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "tofnav/sim/evd_plan.hpp"
#include "tofnav/sim/scenario.hpp"

namespace tofnav {

/// One "Line" markup per trajectory in one file, coordinateSystem LPS, mm: control point 0 is
/// the entry (label "entry"), 1 the target ("target"); the markup's "name" is the trajectory's.
std::string EncodeTrajectoryMarkups(const std::vector<sim::Trajectory>& plan);

/// One "Fiducial" markup "landmarks", coordinateSystem LPS, mm: one control point per landmark,
/// labelled with its name (what tofnav verify reads).
std::string EncodeLandmarkMarkups(const std::vector<sim::PlannedLandmark>& landmarks);
void WriteLandmarkMarkups(const std::filesystem::path& path,
                          const std::vector<sim::PlannedLandmark>& landmarks);

/// Writes EncodeTrajectoryMarkups atomically.
void WriteTrajectoryMarkups(const std::filesystem::path& path,
                            const std::vector<sim::Trajectory>& plan);

}  // namespace tofnav
