// SPDX-License-Identifier: BSD-3-Clause
// The built-in "pivot-calibration" scenario (docs/simulator.md).
#pragma once

#include "tofnav/sim/scenario.hpp"

namespace tofnav::sim {

/// A tracked instrument swung about its tip in a divot (MotionKind::kPivot) beside a static
/// reference tool, seen by a fixed headset: the recording `tofnav pivot` calibrates the tip from.
/// The instrument's true tip is its mount's origin: tip_in_tool = tool_from_mount * 0.
Scenario PivotCalibrationScenario();

}  // namespace tofnav::sim
