// SPDX-License-Identifier: BSD-3-Clause
// The fidelity scenes: the head ones made from the head-identification scene (one upright head
// with forehead stickers on a table) with the protocol's material, camera and length; STTAR's
// sphere tool in front of a fixed headset.
#include "tofnav/sim/scenario_fidelity.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>
#include <random>

#include "tofnav/core/require.hpp"
#include "tofnav/sim/motion.hpp"
#include "tofnav/sim/scenario_builtins.hpp"
#include "tofnav/sim/tool_presets.hpp"

namespace tofnav::sim {
namespace {

constexpr double kSkinStudyMinRangeMm = 180.0;  // the skin study's depths (Sec. III-A)
constexpr double kSkinStudyMaxRangeMm = 500.0;
constexpr double kForeheadElevationRad = 0.35;  // above the nasion: the forehead's middle

// head-identification on `head` with the patient made of `material`.
Scenario HeadOf(const PatientHead& head, const Material& material) {
  Scenario s = BuiltinScenario("head-identification", &head);
  Require(s.patient.has_value(), "head-identification has no patient");
  const SceneObject& skin = s.scene.objects[static_cast<std::size_t>(s.patient->object)];
  Material m = material;
  m.Check();
  s.scene.materials[static_cast<std::size_t>(skin.material)] = m;
  s.timing.drop_probability = 0.0;
  return s;
}

// The fixed headset of MarkerNoiseScenario: 300 mm above the floor, looking along world -z.
Rigid3d SttarWorldFromAhat() {
  const Eigen::Vector3d eye(0.0, 300.0, 0.0);
  return LookAt(eye, eye - Eigen::Vector3d::UnitZ());
}

// The markers' centroid in the tool frame (the point placed at each position).
Eigen::Vector3d SttarCentroidInTool(const Tool& tool) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const Marker& m : tool.markers) sum += m.centre_in_tool;
  return sum / static_cast<double>(tool.markers.size());
}

}  // namespace

void MarkerNoiseProtocol::Check() const {
  Require(positions >= 2, "MarkerNoiseProtocol: positions must be >= 2");
  Require(frames_per_hold >= 1, "MarkerNoiseProtocol: frames_per_hold must be >= 1");
  Require(min_depth_mm > 0.0, "MarkerNoiseProtocol: min_depth_mm must be > 0");
  Require(move_mm > 0.0, "MarkerNoiseProtocol: move_mm must be > 0");
  Require(max_depth_mm - move_mm > min_depth_mm,
          "MarkerNoiseProtocol: max_depth_mm - move_mm must exceed min_depth_mm");
  Require(max_lateral_fraction >= 0.0 && max_lateral_fraction <= 0.5,
          "MarkerNoiseProtocol: max_lateral_fraction must be in [0, 0.5]");
  Require(max_tilt_rad >= 0.0 && max_tilt_rad <= 1.2,
          "MarkerNoiseProtocol: max_tilt_rad must be in [0, 1.2]");
}

std::vector<MarkerNoiseHold> MarkerNoiseHolds(const MarkerNoiseProtocol& protocol) {
  protocol.Check();
  const Eigen::Vector3d centroid =
      SttarCentroidInTool(ToolPreset("spheres-four", kMarkerNoiseToolName, 0));
  std::mt19937_64 rng(protocol.seed * 1000003ULL + 38ULL);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const double span_mm = protocol.max_depth_mm - protocol.move_mm - protocol.min_depth_mm;
  // Facing the camera: the tool's +z (the markers' side) towards -z of `ahat`.
  const Eigen::Quaterniond facing(Eigen::AngleAxisd(std::numbers::pi, Eigen::Vector3d::UnitX()));
  std::vector<MarkerNoiseHold> holds;
  for (int p = 0; p < protocol.positions; ++p) {
    const double depth_mm = protocol.min_depth_mm + span_mm * p / (protocol.positions - 1);
    const double lateral_mm = protocol.max_lateral_fraction * depth_mm;
    const Eigen::Vector3d at(lateral_mm * (2.0 * unit(rng) - 1.0),
                             lateral_mm * (2.0 * unit(rng) - 1.0), depth_mm);
    const double tilt_axis_rad = 2.0 * std::numbers::pi * unit(rng);
    const double tilt_rad = protocol.max_tilt_rad * unit(rng);
    const double spin_rad = 2.0 * std::numbers::pi * unit(rng);
    const Eigen::Quaterniond rotation =
        Eigen::AngleAxisd(tilt_rad,
                          Eigen::Vector3d(std::cos(tilt_axis_rad), std::sin(tilt_axis_rad), 0.0)) *
        facing * Eigen::AngleAxisd(spin_rad, Eigen::Vector3d::UnitZ());
    const Rigid3d still(rotation, at - rotation * centroid);
    for (const bool moved : {false, true}) {
      MarkerNoiseHold hold;
      hold.position = p;
      hold.moved = moved;
      hold.first_slot = static_cast<std::int64_t>(holds.size()) * protocol.frames_per_hold;
      hold.frames = protocol.frames_per_hold;
      hold.ahat_from_tool = still;
      if (moved) hold.ahat_from_tool.translation.z() += protocol.move_mm;
      holds.push_back(hold);
    }
  }
  return holds;
}

Scenario MarkerNoiseScenario(const MarkerNoiseProtocol& protocol) {
  const std::vector<MarkerNoiseHold> holds = MarkerNoiseHolds(protocol);
  Scenario s;
  s.name = "marker-noise";
  s.description =
      "A four-sphere tool (11.5 mm) held static in front of a fixed headset at 350-700 mm, each "
      "pose then moved 20 mm along the camera's z (STTAR's marker protocol)";
  s.seed = protocol.seed;
  const int retro = s.scene.AddMaterial(RetroReflectiveMaterial());
  const Rigid3d world_from_ahat = SttarWorldFromAhat();
  s.camera.motion = StaticMotion(world_from_ahat);
  std::vector<Motion> segments;
  for (const MarkerNoiseHold& hold : holds) {
    Motion segment = StaticMotion(world_from_ahat * hold.ahat_from_tool);
    segment.segment_slots = hold.frames;
    segments.push_back(std::move(segment));
  }
  const int mount = s.AddMount("sphere_holder", SequenceMotion(std::move(segments)));
  s.AddTool(ToolPreset("spheres-four", kMarkerNoiseToolName, retro), mount);
  s.timing.drop_probability = 0.0;
  s.timing.slot_stride = 1;
  s.frames = static_cast<std::int64_t>(holds.size()) * protocol.frames_per_hold;
  return s;
}

Material SkinParticipant(std::uint64_t seed, int index, const SkinSpread& spread) {
  std::mt19937_64 rng(seed * 1000003ULL + static_cast<std::uint64_t>(index));
  Material m = SkinMaterial();
  std::normal_distribution<double> delay(m.subsurface_delay_ps, spread.delay_sd_ps);
  std::uniform_real_distribution<double> albedo(spread.min_albedo, spread.max_albedo);
  m.subsurface_delay_ps = std::max(0.0, delay(rng));
  m.albedo = albedo(rng);
  return m;
}

Scenario SkinStudyScenario(const PatientHead& head, const Material& skin, std::int64_t frames) {
  Scenario s = HeadOf(head, skin);
  s.name = "skin-study";
  s.description =
      "A participant's head with four 10 mm forehead stickers, a headset worn 180-500 mm away "
      "(the skin study of Sec. III-A)";
  Require(s.camera.motion.kind == MotionKind::kHeadWorn, "head-identification's camera is worn");
  s.camera.motion.head_worn.min_range_mm = kSkinStudyMinRangeMm;
  s.camera.motion.head_worn.max_range_mm = kSkinStudyMaxRangeMm;
  s.frames = frames;
  return s;
}

Scenario FacingPhantomScenario(const PatientHead& head, const Material& material,
                               double distance_mm, std::int64_t frames) {
  Require(distance_mm > 0.0, "FacingPhantomScenario: distance_mm must be > 0");
  Scenario s = HeadOf(head, material);
  s.name = "facing-phantom";
  s.description =
      "A head phantom static, a fixed headset square in front of its forehead "
      "(Table I's protocol)";
  const auto object = static_cast<std::size_t>(s.patient->object);
  const int mount = s.object_mounts[object];
  Require(mount >= 0, "head-identification's head is on a mount");
  const Rigid3d world_from_image =
      MotionPose(s.mounts[static_cast<std::size_t>(mount)].motion, 0, s.timing.rate_hz, s.seed) *
      s.scene.objects[object].scene_from_object;
  const Eigen::Vector3d direction =
      HeadDirection(0.0, head.anatomy.nasion_elevation_rad + kForeheadElevationRad);
  const Eigen::Vector3d forehead = head.Probe().RequireHit(direction, "forehead").point;
  const Eigen::Vector3d target = world_from_image * forehead;
  const Eigen::Vector3d outward =
      (world_from_image.rotation * (forehead - head.anatomy.centre_in_image)).normalized();
  const Eigen::Vector3d up = world_from_image.rotation * Eigen::Vector3d::UnitZ();  // superior
  s.camera.motion = StaticMotion(LookAt(target + distance_mm * outward, target, up));
  s.frames = frames;
  return s;
}

}  // namespace tofnav::sim
