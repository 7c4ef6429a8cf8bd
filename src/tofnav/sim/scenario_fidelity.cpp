// SPDX-License-Identifier: BSD-3-Clause
// The fidelity scenes, made from the head-identification scene (one upright head with forehead
// stickers on a table) with the protocol's material, camera and length.
#include "tofnav/sim/scenario_fidelity.hpp"

#include <Eigen/Geometry>
#include <random>

#include "tofnav/core/require.hpp"
#include "tofnav/sim/motion.hpp"
#include "tofnav/sim/scenario_builtins.hpp"

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

}  // namespace

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
