// SPDX-License-Identifier: BSD-3-Clause
// tofnav verify to 3D Slicer: the planned landmarks, the touches and the check's line
// (docs/navigation.md section 7).
#pragma once

#include <vector>

#include "tofnav/pipeline/landmark_check.hpp"
#include "tofnav/stream/navigation_messages.hpp"

namespace tofnav {

/// POINT "Landmarks": the planned landmarks in RAS (yellow), for a client's greeting.
NamedMessage EncodeLandmarksGreeting(const std::vector<Landmark>& landmarks);

/// After each touch and at the start: STRING "VerifyStatus" (LandmarkCheck::StatusLine) and,
/// once a landmark was touched, POINT "VerifyTouches": each touched tip in RAS named
/// "<landmark> <error> mm", green when it passed, red when not.
std::vector<NamedMessage> EncodeLandmarkCheck(const LandmarkCheck& check, double timestamp_s);

}  // namespace tofnav
