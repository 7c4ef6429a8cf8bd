// SPDX-License-Identifier: BSD-3-Clause
// Planned EVD trajectories on a head: Kocher's point burr holes to the frontal horns.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "tofnav/core/triangle_mesh.hpp"
#include "tofnav/sim/mesh_probe.hpp"
#include "tofnav/sim/synthetic_ct.hpp"

namespace tofnav::sim {

/// A planned straight trajectory in `image` (CT LPS) [mm]: entry on the skin, target inside.
struct Trajectory {
  std::string name;
  Eigen::Vector3d entry_in_image = Eigen::Vector3d::Zero();
  Eigen::Vector3d target_in_image = Eigen::Vector3d::Zero();
};

struct EvdPlanOptions {
  double kocher_arc_mm = 110.0;     // along the midline scalp, posterior to the nasion
  double kocher_lateral_mm = 30.0;  // from the midline
  double top_posterior_mm = 15.0;   // the midline hole sits this far behind the Kocher arc point
  double entry_spread_mm = 6.0;     // spacing of the three entries around each hole
  void Check() const;
};

/// Nine trajectories, three per burr hole (as in the paper's use case): holes at the right and
/// left Kocher's points and one on the midline between them (top). Side holes aim at the
/// ipsilateral frontal horn tip, the frontal horn body and the foramen of Monro; the top hole at
/// both frontal horn tips and the right foramen. Entries are skin points near the
/// hole found by casting from the anatomy centre; names "right-1" .. "top-3".
/// Throws PreconditionError when the skin is not hit (a mesh that does not enclose the centre).
std::vector<Trajectory> PlanEvdTrajectories(const TriangleMesh& skin_in_image,
                                            const HeadAnatomy& anatomy,
                                            const EvdPlanOptions& options = {});
/// The same with a probe of the skin whose rays start at the anatomy centre (PreconditionError
/// otherwise), to share its set-up cost.
std::vector<Trajectory> PlanEvdTrajectories(const MeshProbe& skin, const HeadAnatomy& anatomy,
                                            const EvdPlanOptions& options = {});

}  // namespace tofnav::sim
