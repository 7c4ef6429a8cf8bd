// SPDX-License-Identifier: BSD-3-Clause
// Scenario sanity: markers must not reach into the other surfaces of the scene (a sphere sunk
// into the scalp, a disc under a plate), checked at the slots where motions change course.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "tofnav/sim/scenario.hpp"

namespace tofnav::sim {

/// A marker that reaches into a scene object.
struct MarkerIntersection {
  int tool = -1;
  int marker = -1;  // index within the tool (as in truth.json)
  int object = -1;  // the surface it reaches into
  double depth_mm = 0.0;
  std::int64_t slot = 0;  // the first checked slot with this depth
};

struct MarkerClearanceOptions {
  /// Deeper intersections are errors. A sticker follows the skin's interpolated normal, so on a
  /// coarse mesh its rim dips under a facet by about r sin(facet angle / 2): 0.4 mm for a 10 mm
  /// disc on a 48-segment phantom, 0.1 mm on the default 192 (docs/simulator.md section 6.11).
  double tolerance_mm = 0.5;
  int sphere_rays = 640;  // directions from a sphere's centre (plus the six axes)
  int max_slots = 64;     // at most this many of the checked slots (the earliest)
  void Check() const;
};

/// The deepest intersection of every marker that reaches more than tolerance_mm into a scene
/// object, deepest first. Checked at slot 0 and at the key slots (MotionKeySlots) of every
/// mount's motion below scenario.frames. A sphere is probed by rays from its centre: a surface
/// met at t < r from its front reaches r - t into it, from its back (or a closed mesh around the
/// centre) r + t. A disc is probed at its centre and eight points at 0.9 of its radius by rays
/// along its normal: a surface met from its back within a radius (any distance for a closed
/// mesh) buries the point by t.
std::vector<MarkerIntersection> FindMarkerIntersections(const Scenario& scenario,
                                                        const MarkerClearanceOptions& options = {});

/// One line: "scenario: tool 'T' marker 2 (sphere, 11.5 mm) intersects the head surface by
/// 3.1 mm" (", at slot S" when S > 0).
std::string DescribeMarkerIntersection(const Scenario& scenario, const MarkerIntersection& hit);

/// Throws PreconditionError whose what() is DescribeMarkerIntersection of the deepest, if any.
void RequireMarkersClear(const Scenario& scenario, const MarkerClearanceOptions& options = {});

}  // namespace tofnav::sim
