// SPDX-License-Identifier: BSD-3-Clause
// Scenario bookkeeping and consistency checks.
#include "tofnav/sim/scenario.hpp"

#include <algorithm>
#include <set>
#include <utility>

#include "tofnav/core/require.hpp"

namespace tofnav::sim {
namespace {

bool IsSafeName(const std::string& name) {
  return !name.empty() && name.size() <= 64 && std::all_of(name.begin(), name.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
           c == '-';
  });
}

template <typename Items, typename Name>
int FindByName(const Items& items, const std::string& wanted, Name name) {
  for (std::size_t i = 0; i < items.size(); ++i) {
    if (name(items[i]) == wanted) return static_cast<int>(i);
  }
  return -1;
}

}  // namespace

CameraSetup::CameraSetup() {
  calibration.rig_from_ahat = TypicalRigFromAhat();
  // hl2ss >= v1.0.36 tables (s = 0): with the synthetic pinhole's fx == fy, readers of the
  // calibration folder recover s by the auto rule of docs/ahat.md 5.3.
  calibration.sample_offset_px = 0.0;
}

const Rigid3d& CameraSetup::RigFromAhat() const {
  return device ? device->rig_from_ahat : calibration.rig_from_ahat;
}

int Scenario::AddMount(std::string mount_name, Motion motion) {
  mounts.push_back({std::move(mount_name), std::move(motion)});
  return static_cast<int>(mounts.size()) - 1;
}

int Scenario::AddObject(std::string object_name, TriangleMesh mesh, int material, int mount,
                        const Rigid3d& mount_from_object) {
  object_mounts.push_back(mount);
  return scene.AddObject(std::move(object_name), std::move(mesh), material, mount_from_object);
}

int Scenario::AddTool(Tool tool, int mount) {
  tool_mounts.push_back(mount);
  return scene.AddTool(std::move(tool));
}

int Scenario::FindMaterial(const std::string& material_name) const {
  return FindByName(scene.materials, material_name, [](const Material& m) { return m.name; });
}

int Scenario::FindMount(const std::string& mount_name) const {
  return FindByName(mounts, mount_name, [](const Mount& m) { return m.name; });
}

int Scenario::FindObject(const std::string& object_name) const {
  return FindByName(scene.objects, object_name, [](const SceneObject& o) { return o.name; });
}

std::vector<int> Scenario::ToolsRigidWithPatient() const {
  std::vector<int> tools;
  if (!patient || patient->object < 0) return tools;
  const int mount = object_mounts[static_cast<std::size_t>(patient->object)];
  for (std::size_t t = 0; t < tool_mounts.size(); ++t) {
    if (tool_mounts[t] == mount) tools.push_back(static_cast<int>(t));
  }
  return tools;
}

void Scenario::Check() const {
  Require(IsSafeName(name), "Scenario.name must be 1-64 characters of [A-Za-z0-9_-]");
  Require(frames >= 1, "Scenario.frames must be >= 1");
  scene.Check();
  Require(object_mounts.size() == scene.objects.size() && tool_mounts.size() == scene.tools.size(),
          "Scenario: object_mounts/tool_mounts must match the scene's objects and tools");
  const int mount_count = static_cast<int>(mounts.size());
  for (const int m : object_mounts)
    Require(m >= -1 && m < mount_count, "Scenario: bad object mount");
  for (const int m : tool_mounts) Require(m >= -1 && m < mount_count, "Scenario: bad tool mount");
  std::set<std::string> names;
  const auto unique_name = [&](const std::string& n, const char* what) {
    Require(IsSafeName(n), std::string("Scenario: ") + what + " name '" + n +
                               "' must be 1-64 characters of [A-Za-z0-9_-]");
    Require(names.insert(n).second, "Scenario: the name '" + n + "' is used twice");
  };
  for (const Mount& m : mounts) {
    unique_name(m.name, "mount");
    m.motion.Check();
  }
  for (const SceneObject& o : scene.objects) unique_name(o.name, "object");
  for (const Tool& t : scene.tools) {
    unique_name(t.name, "tool");
    Require(!t.markers.empty(), "Scenario: tool '" + t.name + "' has no markers");
  }
  std::set<std::string> material_names;
  for (const Material& m : scene.materials) {
    Require(material_names.insert(m.name).second,
            "Scenario: the material name '" + m.name + "' is used twice");
  }
  Require(names.count("world") == 0 && names.count("camera") == 0,
          "Scenario: 'world' and 'camera' are reserved names");
  camera.calibration.Check();
  camera.motion.Check();
  camera.slam.Check();
  timing.Check();
  render.Check();
  if (patient) {
    Require(patient->object >= 0 && patient->object < static_cast<int>(scene.objects.size()),
            "Scenario.patient.object must name a scene object");
    Require((patient->anatomy.semi_axes_mm.array() > 0.0).all() &&
                patient->anatomy.centre_in_image.allFinite(),
            "Scenario.patient.anatomy must have positive semi-axes");
    patient->ct.Check();
  }
}

}  // namespace tofnav::sim
