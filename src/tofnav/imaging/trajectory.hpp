// SPDX-License-Identifier: BSD-3-Clause
// A planned straight trajectory (entry on the scalp, target in the brain) in the image frame.
#pragma once

#include <Eigen/Core>
#include <string>

namespace tofnav {

/// One planned trajectory in `image` (patient LPS, mm), e.g. an EVD catheter from Kocher's point
/// to the foramen of Monro. Read from 3D Slicer markups by io/ (ReadTrajectories).
struct Trajectory {
  std::string name;
  Eigen::Vector3d entry_lps_mm = Eigen::Vector3d::Zero();
  Eigen::Vector3d target_lps_mm = Eigen::Vector3d::Zero();
};

}  // namespace tofnav
