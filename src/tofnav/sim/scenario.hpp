// SPDX-License-Identifier: BSD-3-Clause
// A simulation scenario: scene, moving mounts, the headset camera, timing, sensor effects and an
// optional patient (head, CT, plan). Built-ins or io/scenario_json fill it.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "tofnav/core/rigid3d.hpp"
#include "tofnav/sensor/ahat_calibration.hpp"
#include "tofnav/sim/evd_plan.hpp"
#include "tofnav/sim/motion.hpp"
#include "tofnav/sim/render.hpp"
#include "tofnav/sim/scene.hpp"
#include "tofnav/sim/synthetic_ct.hpp"
#include "tofnav/sim/timing.hpp"

namespace tofnav::sim {

/// A rigidly moving frame that objects and tools ride on (linear stage, platform, headframe).
struct Mount {
  std::string name;
  Motion motion;  // gives world_from_mount
};

/// The headset: its AHAT calibration (rig_from_ahat inside), how it moves, how it reports poses.
struct CameraSetup {
  /// rig_from_ahat defaults to TypicalRigFromAhat(), sample_offset_px to 0 (hl2ss >= v1.0.36, so
  /// the written folder reads back unambiguously).
  SyntheticAhatOptions calibration;
  /// A real headset's calibration (scenario key camera.calibration.folder): when set, frames are
  /// rendered with its unit rays and rig_from_ahat, `calibration` is unused, and the session's
  /// calibration folder is written as that device's, byte for byte.
  std::shared_ptr<const AhatCalibration> device;
  std::string device_folder;  // where `device` was read from, for reports and the truth file
  Motion motion;              // gives world_from_ahat (the camera, not the rig)
  SlamJitterOptions slam;
  CameraSetup();
  /// The rendered camera's extrinsics: the device's when set, else the synthetic model's.
  const Rigid3d& RigFromAhat() const;
};

/// A landmark on the skin in `image` coordinates [mm], and when a scenario's pointer touches it.
struct PlannedLandmark {
  std::string name;
  Eigen::Vector3d in_image = Eigen::Vector3d::Zero();
  std::int64_t touch_first_slot = -1;  // the tip rests on it from this slot ...
  std::int64_t touch_last_slot = -1;   // ... to this one (-1: never touched)
};

/// The patient: a head whose skin is one scene object, meshed in `image` (CT LPS) coordinates.
struct Patient {
  std::string head_source = "phantom";  // "phantom" or "mesh:<path>", for reports
  int object = -1;      // scene object holding the skin; its pose is mount_from_image
  HeadAnatomy anatomy;  // in image coordinates: ventricles, plan landmarks
  bool write_ct = true;
  SyntheticCtOptions ct;
  std::vector<Trajectory> plan;  // in image coordinates
  /// Anatomical landmarks planned in the image for the accuracy check before guidance (tofnav
  /// verify), and the frame slots in which the scenario's pointer rests on each (empty: none).
  std::vector<PlannedLandmark> landmarks;
};

struct Scenario {
  std::string name;
  std::string description;
  std::uint64_t seed = 1;
  std::int64_t frames = 100;  // frames written (dropped slots do not count)
  /// Geometry and materials. A pose in it is relative to its mount: scene_from_object holds
  /// mount_from_object, scene_from_tool holds mount_from_tool (world_from_* when unmounted).
  Scene scene;
  std::vector<Mount> mounts;
  std::vector<int> object_mounts;  // per scene object: index into mounts, -1 = static in world
  std::vector<int> tool_mounts;    // per scene tool
  CameraSetup camera;
  FrameTimingOptions timing;
  RenderOptions render;
  std::optional<Patient> patient;

  int AddMount(std::string mount_name, Motion motion);
  /// Adds an object riding on `mount` (-1: static in world) at mount_from_object.
  int AddObject(std::string object_name, TriangleMesh mesh, int material, int mount,
                const Rigid3d& mount_from_object);
  /// Adds a tool riding on `mount`; tool.scene_from_tool is read as mount_from_tool.
  int AddTool(Tool tool, int mount);
  /// Index of the material called `material_name`, or -1.
  int FindMaterial(const std::string& material_name) const;
  int FindMount(const std::string& mount_name) const;
  int FindObject(const std::string& object_name) const;
  /// Tools on the patient's mount (rigid with the patient); empty without a patient.
  std::vector<int> ToolsRigidWithPatient() const;
  /// Throws PreconditionError naming the problem: bad indices, duplicate or unsafe names (names
  /// are [A-Za-z0-9_-]+, unique among objects, tools and mounts), bad options.
  void Check() const;
};

}  // namespace tofnav::sim
