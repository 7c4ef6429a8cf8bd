// SPDX-License-Identifier: BSD-3-Clause
// The evd-usecase scenario as a navigation case with its truth: tools, f_rf, tool_from_image.
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

#include "e2e_common.hpp"
#include "tofnav/pipeline/navigator.hpp"
#include "tofnav/sim/scenario_builtins.hpp"
#include "tofnav/sim/simulator.hpp"

namespace tofnav::testing {

/// A tracking definition of a simulated tool (its true marker centres).
inline ToolGeometry ToolFromSim(const sim::Tool& tool) {
  ToolGeometry g;
  g.name = tool.name;
  for (const sim::Marker& m : tool.markers) g.markers_in_tool.push_back(m.centre_in_tool);
  g.marker_type = tool.markers.front().shape == sim::MarkerShape::kDisc ? MarkerType::kDisc
                                                                        : MarkerType::kSphere;
  g.marker_diameter_mm = tool.markers.front().diameter_mm;
  return g;
}

struct EvdCase {
  sim::Scenario scenario;
  int reference = -1;       // scene tool index of the reference ("reference_left")
  int instrument = -1;      // the other headframe tool, used as an instrument with a virtual tip
  Rigid3d tool_from_image;  // truth
  Rigid3d instrument_from_image;  // truth
  NavigationCase navigation_case;
};

/// evd-usecase with `frames` frames; the plan and f_rf from the truth. The reference is both
/// headframe tools joined into one (docs/frames.md: rigidly joined tools count as one) in the
/// frame of "reference_left". With `instrument`, the reference is "reference_left" alone and
/// "reference_right" is tracked as an instrument whose virtual tip lies 10 mm before the entry
/// of trajectory 0 on its planned line (guidance truth: 10 mm, 0 rad, 10 mm + length).
inline EvdCase MakeEvdCase(std::int64_t frames, bool instrument) {
  EvdCase c;
  c.scenario = sim::BuiltinScenario("evd-usecase");
  c.scenario.frames = frames;
  const sim::Scene& scene = c.scenario.scene;
  for (int i = 0; i < static_cast<int>(scene.tools.size()); ++i) {
    if (scene.tools[static_cast<std::size_t>(i)].name == "reference_left") c.reference = i;
    if (scene.tools[static_cast<std::size_t>(i)].name == "reference_right") c.instrument = i;
  }
  const auto& patient = *c.scenario.patient;
  const Rigid3d mount_from_image =
      scene.objects[static_cast<std::size_t>(patient.object)].scene_from_object;
  const auto& ref = scene.tools[static_cast<std::size_t>(c.reference)];
  c.tool_from_image = ref.scene_from_tool.Inverse() * mount_from_image;
  NavigationCase& n = c.navigation_case;
  n.reference = ToolFromSim(ref);
  const auto& other = scene.tools[static_cast<std::size_t>(c.instrument)];
  if (!instrument) {
    const Rigid3d left_from_right = ref.scene_from_tool.Inverse() * other.scene_from_tool;
    for (const sim::Marker& m : other.markers) {
      n.reference.markers_in_tool.push_back(left_from_right * m.centre_in_tool);
    }
    n.reference.name = "Reference";
  }
  n.tool_from_image = c.tool_from_image;
  for (const sim::Trajectory& t : patient.plan) {
    n.plan.push_back({t.name, t.entry_in_image, t.target_in_image});
  }
  const sim::Material& retro =
      scene.materials[static_cast<std::size_t>(ref.markers.front().material)];
  n.marker_range = TrueRangeModel(retro, c.scenario.render.sensor);
  if (instrument) {
    c.instrument_from_image = other.scene_from_tool.Inverse() * mount_from_image;
    const Trajectory& t = n.plan.front();
    const Eigen::Vector3d u = (t.target_lps_mm - t.entry_lps_mm).normalized();
    ToolGeometry g = ToolFromSim(other);
    g.tip_in_tool = c.instrument_from_image * (t.entry_lps_mm - 10.0 * u);
    n.instrument = g;
  }
  return c;
}

/// The planned direction of the instrument's virtual axis in its own frame (see MakeEvdCase).
inline Eigen::Vector3d InstrumentAxisInTool(const EvdCase& c) {
  const Trajectory& t = c.navigation_case.plan.front();
  return c.instrument_from_image.rotation * (t.target_lps_mm - t.entry_lps_mm).normalized();
}

inline double Percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(std::lround(q * static_cast<double>(v.size() - 1)))];
}

}  // namespace tofnav::testing
