// SPDX-License-Identifier: BSD-3-Clause
// GoogleMock matchers shared by the test suites.
#pragma once

#include <gmock/gmock.h>

#include <cmath>
#include <ostream>

#include "tofnav/core/rigid3d.hpp"

namespace tofnav {

inline void PrintTo(const Rigid3d& t, std::ostream* os) {
  *os << "Rigid3d{q=(" << t.rotation.w() << ", " << t.rotation.x() << ", " << t.rotation.y() << ", "
      << t.rotation.z() << "), t=(" << t.translation.transpose() << ") mm}";
}

/// Matches a Rigid3d within `rot_tol_rad` of rotation angle and `trans_tol_mm` of translation.
MATCHER_P3(RigidNear, expected, rot_tol_rad, trans_tol_mm,
           "is within " + ::testing::PrintToString(rot_tol_rad) + " rad and " +
               ::testing::PrintToString(trans_tol_mm) + " mm of the expected transform") {
  const double rot = RotationDistanceRad(arg, expected);
  const double trans = TranslationDistanceMm(arg, expected);
  *result_listener << "rotation error " << rot << " rad, translation error " << trans << " mm";
  return rot <= rot_tol_rad && trans <= trans_tol_mm;
}

}  // namespace tofnav
