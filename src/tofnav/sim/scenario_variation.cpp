// SPDX-License-Identifier: BSD-3-Clause
// Scenario variations of the robustness suite (docs/simulator.md, "Scenario variations").
#include "tofnav/sim/scenario_variation.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <initializer_list>
#include <random>
#include <utility>

#include "tofnav/core/require.hpp"
#include "tofnav/core/rotation_vector.hpp"
#include "tofnav/sim/evd_occluders.hpp"
#include "tofnav/sim/material.hpp"
#include "tofnav/sim/shapes.hpp"

namespace tofnav::sim {
namespace {

constexpr double kSphereDiameterMm = 11.5;  // the usual passive sphere
constexpr double kPostMm = 8.0;             // from the plate to the sphere's base
constexpr double kPillowMarginMm = 15.0;    // clearance between the pillow and the head's box

bool IsReference(const Tool& tool) { return tool.name.starts_with("reference"); }

std::vector<int> ReferenceToolsOnPatient(const Scenario& s) {
  std::vector<int> found;
  for (const int t : s.ToolsRigidWithPatient()) {
    if (IsReference(s.scene.tools[static_cast<std::size_t>(t)])) found.push_back(t);
  }
  return found;
}

void RemoveToolsIf(Scenario& s, const std::function<bool(const Tool&)>& remove) {
  std::vector<Tool> tools;
  std::vector<int> mounts;
  for (std::size_t t = 0; t < s.scene.tools.size(); ++t) {
    if (remove(s.scene.tools[t])) continue;
    tools.push_back(std::move(s.scene.tools[t]));
    mounts.push_back(s.tool_mounts[t]);
  }
  s.scene.tools = std::move(tools);
  s.tool_mounts = std::move(mounts);
}

// Removes the objects whose name `remove` selects; the patient's skin object is kept. Stickers
// that conformed to a removed object become rigid discs; the others follow the new indices.
void RemoveObjectsIf(Scenario& s, const std::function<bool(const std::string&)>& remove) {
  std::vector<SceneObject> objects;
  std::vector<int> mounts;
  std::vector<int> new_index(s.scene.objects.size(), -1);
  for (std::size_t o = 0; o < s.scene.objects.size(); ++o) {
    const bool skin = s.patient && static_cast<int>(o) == s.patient->object;
    if (!skin && remove(s.scene.objects[o].name)) continue;
    new_index[o] = static_cast<int>(objects.size());
    objects.push_back(std::move(s.scene.objects[o]));
    mounts.push_back(s.object_mounts[o]);
  }
  s.scene.objects = std::move(objects);
  s.object_mounts = std::move(mounts);
  if (s.patient) s.patient->object = new_index[static_cast<std::size_t>(s.patient->object)];
  for (Tool& tool : s.scene.tools) {
    for (Marker& m : tool.markers) {
      if (m.conforms_to_object >= 0)
        m.conforms_to_object = new_index[static_cast<std::size_t>(m.conforms_to_object)];
    }
  }
}

bool NamedLike(const std::string& name, std::initializer_list<const char*> prefixes) {
  return std::any_of(prefixes.begin(), prefixes.end(),
                     [&](const char* p) { return name.starts_with(p); });
}

// Each disc of a reference plate becomes a sphere on a post above the same point of the plate.
void TapeToSpheres(Tool& tool) {
  for (Marker& m : tool.markers) {
    const Eigen::Vector3d normal = m.normal_in_tool.normalized();
    const Eigen::Vector3d on_plate = m.centre_in_tool - normal * normal.dot(m.centre_in_tool);
    m.shape = MarkerShape::kSphere;
    m.conforms_to_object = -1;
    m.diameter_mm = kSphereDiameterMm;
    m.centre_in_tool = on_plate + normal * (kPostMm + kSphereDiameterMm / 2.0);
  }
}

// A bright fabric pillow (ellipsoid 360 x 140 x 260 mm) against the back of the head, on the
// patient's mount, clear of the head's bounding box.
void AddPillow(Scenario& s) {
  const SceneObject& skin = s.scene.objects[static_cast<std::size_t>(s.patient->object)];
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e30), hi = -lo;
  for (const Eigen::Vector3d& v : skin.mesh.vertices) {
    const Eigen::Vector3d p = skin.scene_from_object * v;  // mount frame
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const Eigen::Vector3d semi(180.0, 70.0, 130.0);
  // LPS +y is posterior: the pillow sits behind the head, centred on its height.
  const Eigen::Vector3d centre(0.5 * (lo.x() + hi.x()), hi.y() + semi.y() + kPillowMarginMm,
                               0.5 * (lo.z() + hi.z()));
  TriangleMesh mesh = SphereMesh(1.0, 48);
  for (Eigen::Vector3d& v : mesh.vertices) v = v.cwiseProduct(semi);
  for (Eigen::Vector3d& n : mesh.vertex_normals) n = n.cwiseQuotient(semi).normalized();
  Material fabric = DiffuseMaterial(0.8);
  fabric.name = "pillow_fabric";
  int material = s.FindMaterial(fabric.name);
  if (material < 0) material = s.scene.AddMaterial(fabric);
  const int mount = s.object_mounts[static_cast<std::size_t>(s.patient->object)];
  s.AddObject("pillow", std::move(mesh), material, mount,
              Rigid3d(Eigen::Quaterniond::Identity(), centre));
}

}  // namespace

void ScenarioVariation::Check() const {
  Require(head_drift_mm_per_s >= 0.0 && std::isfinite(head_drift_mm_per_s),
          "ScenarioVariation.head_drift_mm_per_s must be >= 0");
  Require(head_drift_mm > 0.0, "ScenarioVariation.head_drift_mm must be > 0");
  Require(drop_probability < 1.0, "ScenarioVariation.drop_probability must be < 1");
  Require(mean_drop_slots < 0.0 || mean_drop_slots >= 1.0,
          "ScenarioVariation.mean_drop_slots must be >= 1");
  Require(std::isfinite(skin_albedo) && skin_albedo <= 1.0,
          "ScenarioVariation.skin_albedo must be <= 1 (< 0: the scenario's material)");
  Require(std::isfinite(headset_min_range_mm) && std::isfinite(headset_max_range_mm),
          "ScenarioVariation.headset_min_range_mm / headset_max_range_mm must be finite");
}

void ApplyVariation(const ScenarioVariation& v, Scenario& s) {
  v.Check();
  Require(s.patient.has_value(), "ApplyVariation: the scenario has no patient");
  const std::vector<int> references = ReferenceToolsOnPatient(s);
  if (v.tools != ReferenceTools::kAsBuilt) {
    Require(!references.empty(), "ApplyVariation: the scenario has no reference tool");
  }
  if (v.tools == ReferenceTools::kSpheres) {
    for (const int t : references) TapeToSpheres(s.scene.tools[static_cast<std::size_t>(t)]);
  } else if (v.tools == ReferenceTools::kSingleTool && references.size() > 1) {
    const std::string keep = s.scene.tools[static_cast<std::size_t>(references.front())].name;
    std::vector<std::string> plates;
    for (std::size_t i = 1; i < references.size(); ++i) {
      plates.push_back(s.scene.tools[static_cast<std::size_t>(references[i])].name + "_plate");
    }
    RemoveToolsIf(s, [&](const Tool& t) { return IsReference(t) && t.name != keep; });
    RemoveObjectsIf(s, [&](const std::string& name) {
      return std::find(plates.begin(), plates.end(), name) != plates.end();
    });
  }
  if (!v.occluders) {
    RemoveToolsIf(s, [](const Tool& t) { return NamedLike(t.name, {"hand", "instrument"}); });
    RemoveObjectsIf(s, [](const std::string& n) { return NamedLike(n, {"hand", "instrument"}); });
  }
  if (v.surroundings == Surroundings::kBare) {
    RemoveObjectsIf(s, [](const std::string& n) { return NamedLike(n, {"drape", "pillow"}); });
  } else if (v.surroundings == Surroundings::kPillow) {
    AddPillow(s);
  }
  if (v.head_drift_mm_per_s > 0.0) {
    Motion& motion = s.mounts[static_cast<std::size_t>(
                                  s.object_mounts[static_cast<std::size_t>(s.patient->object)])]
                         .motion;
    Require(motion.kind == MotionKind::kStatic, "ApplyVariation: the patient already moves");
    motion = LinearStageMotion(motion.start, Eigen::Vector3d(0.6, 0.3, 0.74), v.head_drift_mm_per_s,
                               v.head_drift_mm);
  }
  if (v.drop_probability >= 0.0) s.timing.drop_probability = v.drop_probability;
  if (v.mean_drop_slots >= 1.0) s.timing.mean_drop_slots = v.mean_drop_slots;
  if (v.no_hand_rate_hz >= 0.0) s.timing.no_hand_rate_hz = v.no_hand_rate_hz;
  if (v.slam_translation_sigma_mm >= 0.0) {
    s.camera.slam.translation_sigma_mm = v.slam_translation_sigma_mm;
  }
  if (v.slam_rotation_sigma_rad >= 0.0)
    s.camera.slam.rotation_sigma_rad = v.slam_rotation_sigma_rad;
  if (v.skin_albedo >= 0.0) {
    // A material of its own: the head's print material may be shared with other objects, and
    // the scene may have skin already (evd-usecase's hand).
    Material skin = SkinMaterial();
    skin.name = "patient_skin";
    skin.albedo = v.skin_albedo;
    s.scene.objects[static_cast<std::size_t>(s.patient->object)].material =
        s.scene.AddMaterial(skin);
  }
  if (v.headset_min_range_mm >= 0.0 || v.headset_max_range_mm >= 0.0) {
    Require(s.camera.motion.kind == MotionKind::kHeadWorn,
            "ApplyVariation: the headset's range needs a head-worn camera motion");
    HeadWornMotion& worn = s.camera.motion.head_worn;
    if (v.headset_min_range_mm >= 0.0) worn.min_range_mm = v.headset_min_range_mm;
    if (v.headset_max_range_mm >= 0.0) worn.max_range_mm = v.headset_max_range_mm;
  }
  // Spheres on posts reach higher than tape, and a drifting patient carries the plate towards the
  // hand hovering over it: the hand's pass is lifted until neither reaches into it.
  ClearEvdHandOverTools(s);
  s.Check();
}

SyntheticAhatOptions PerturbedDevice(const SyntheticAhatOptions& base, std::uint64_t seed,
                                     const DeviceSpread& spread) {
  std::mt19937_64 rng(seed);
  const auto uniform = [&](double half) {
    return std::uniform_real_distribution<double>(-half, half)(rng);
  };
  SyntheticAhatOptions device = base;
  device.focal_px *= 1.0 + uniform(spread.focal_fraction);
  device.principal_point_px +=
      Eigen::Vector2d(uniform(spread.principal_point_px), uniform(spread.principal_point_px));
  const Eigen::Vector3d rotation(uniform(spread.rotation_rad), uniform(spread.rotation_rad),
                                 uniform(spread.rotation_rad));
  const Eigen::Vector3d translation(uniform(spread.translation_mm), uniform(spread.translation_mm),
                                    uniform(spread.translation_mm));
  const Rigid3d delta(FromRotationVector(rotation), translation);
  device.rig_from_ahat = base.rig_from_ahat * delta;
  return device;
}

}  // namespace tofnav::sim
