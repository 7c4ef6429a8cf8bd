// SPDX-License-Identifier: BSD-3-Clause
// "pivot-calibration": world = HoloLens world, +y up, the headset on the +z side.
#include "tofnav/sim/scenario_pivot.hpp"

#include <Eigen/Geometry>
#include <numbers>

#include "tofnav/sim/shapes.hpp"
#include "tofnav/sim/tool_presets.hpp"

namespace tofnav::sim {
namespace {

constexpr double kShaftMm = 150.0;  // tip to the instrument's marker plate

// A preset tool and its 80 x 60 mm plate on `mount` at mount_from_tool.
void AddPlateTool(Scenario& s, const char* preset, const char* name, int mount,
                  const Rigid3d& mount_from_tool, int retro, int plate_material) {
  s.AddObject(std::string(name) + "_plate", PlaneMesh(80.0, 60.0), plate_material, mount,
              mount_from_tool);
  Tool tool = ToolPreset(preset, name, retro);
  tool.scene_from_tool = mount_from_tool;
  s.AddTool(std::move(tool), mount);
}

}  // namespace

Scenario PivotCalibrationScenario() {
  Scenario s;
  s.name = "pivot-calibration";
  s.description =
      "An instrument (four 10 mm discs on a plate 150 mm up its shaft) swung about its tip in a "
      "divot, cone up to 26 deg, beside a static four-disc reference; fixed headset 450-600 mm "
      "away, 450 frames (pivot calibration)";
  const int retro = s.scene.AddMaterial(RetroReflectiveMaterial(RetroCurve::kLinear));
  Material acrylic = DiffuseMaterial(0.45);
  acrylic.name = "acrylic";
  const int plate = s.scene.AddMaterial(std::move(acrylic));
  const Eigen::Vector3d eye(0.0, 350.0, 150.0), divot(0.0, 150.0, -380.0);
  s.camera.motion = StaticMotion(LookAt(eye, divot + Eigen::Vector3d(0.0, 50.0, 40.0)));
  // The table the divot is drilled into (its normal +z turned to +y).
  const Rigid3d table_pose(
      Eigen::Quaterniond(Eigen::AngleAxisd(-0.5 * std::numbers::pi, Eigen::Vector3d::UnitX())),
      divot - Eigen::Vector3d(0.0, 0.5, 0.0));
  s.AddObject("table", PlaneMesh(500.0, 400.0), plate, -1, table_pose);
  const Eigen::Vector3d reference_at(-130.0, 170.0, -380.0);
  AddPlateTool(s, "reference-a", "pivot_reference", -1,
               Rigid3d(LookAt(reference_at, eye).rotation, reference_at), retro, plate);
  // The hand: the shaft (mount +z) at rest points up and towards the headset.
  const Eigen::Vector3d shaft = Eigen::Vector3d(0.0, 0.75, 0.66).normalized();
  Motion swing;
  swing.kind = MotionKind::kPivot;
  swing.start = Rigid3d(LookAt(divot, divot + shaft).rotation, divot);
  const int hand = s.AddMount("instrument_hand", swing);
  const Eigen::Vector3d plate_at = divot + kShaftMm * shaft;
  const Rigid3d mount_from_tool =
      swing.start.Inverse() * Rigid3d(LookAt(plate_at, eye).rotation, plate_at);
  s.AddObject("instrument_shaft", BoxMesh({4.0, 4.0, kShaftMm - 2.0}), plate, hand,
              Rigid3d(Eigen::Quaterniond::Identity(), {0.0, 0.0, 0.5 * kShaftMm - 1.0}));
  AddPlateTool(s, "reference-b", "instrument", hand, mount_from_tool, retro, plate);
  s.frames = 450;
  return s;
}

}  // namespace tofnav::sim
