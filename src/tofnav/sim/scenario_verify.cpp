// SPDX-License-Identifier: BSD-3-Clause
// "verify-landmarks" (docs/simulator.md): poses are built in the headframe mount (`image` moved
// to the anatomy centre: +x the patient's left, +y posterior, +z superior), then put in the world.
#include "tofnav/sim/scenario_verify.hpp"

#include <Eigen/Geometry>

#include "tofnav/core/require.hpp"
#include "tofnav/sim/occluders.hpp"

namespace tofnav::sim {
namespace {

constexpr std::int64_t kVerifyFirstSlot = 30;  // the pointer comes in after 0.7 s
constexpr std::int64_t kVerifyMoveSlots = 20;  // 0.44 s from one landmark's approach to the touch
constexpr std::int64_t kVerifyRestSlots = 72;  // 1.6 s on the landmark
constexpr double kVerifyLiftMm = 60.0;         // approach and leave this far off the skin
constexpr double kVerifyAzimuthSpanRad = 1.0;  // evd-usecase: 1.8
constexpr double kVerifyWanderPeriodS = 12.0;  // evd-usecase: 8
constexpr double kRodUpWeight = 1.0;           // the rod leans up (superior) ...
constexpr double kRodForwardWeight = 0.4;      // ... and forward (anterior) from the skin normal

// The mount `name` of evd-usecase that this scenario re-uses (Scenario::FindMount, required).
Mount& VerifyMount(Scenario& s, const char* name) {
  const int index = s.FindMount(name);
  Require(index >= 0, std::string("verify-landmarks: the scenario has no mount '") + name + "'");
  return s.mounts[static_cast<std::size_t>(index)];
}

// mount_from_tool of the pointer with its tip at `point` and its rod (tool +y, from the tip to
// the markers) along `rod`, the marker plane (tool +z) turned towards the wearer (`facing`).
Rigid3d VerifyPointerPose(const Eigen::Vector3d& point, const Eigen::Vector3d& rod,
                          const Eigen::Vector3d& facing, const Eigen::Vector3d& tip_in_tool) {
  const Eigen::Vector3d y = rod.normalized();
  const Eigen::Vector3d z = (facing - facing.dot(y) * y).normalized();
  Eigen::Matrix3d axes;
  axes << y.cross(z), y, z;
  const Eigen::Quaterniond rotation(axes);
  return {rotation, point - rotation * tip_in_tool};
}

}  // namespace

std::vector<PlannedLandmark> VerifyLandmarks(const PatientHead& head) {
  const double eye_level = head.anatomy.nasion_elevation_rad;
  const std::pair<const char*, Eigen::Vector3d> where[] = {
      {"nasion", HeadDirection(0.0, eye_level)},
      {"right_lateral_canthus", HeadDirection(-0.6, eye_level - 0.05)},
      {"left_lateral_canthus", HeadDirection(0.6, eye_level - 0.05)},
      {"forehead", HeadDirection(0.0, eye_level + 0.45)}};
  std::vector<PlannedLandmark> landmarks;
  for (const auto& [name, direction] : where) {
    landmarks.push_back({name, head.Probe().RequireHit(direction, name).point});
  }
  return landmarks;
}

Scenario VerifyLandmarksScenario(Scenario s, const PatientHead& head) {
  Require(s.patient.has_value(), "verify-landmarks: the scenario has no patient");
  s.name = "verify-landmarks";
  s.description =
      "evd-usecase's patient and headframe; a pointer rests 1.6 s on each of four skin landmarks "
      "(nasion, lateral canthi, forehead) in turn while a wandering headset looks on, 568 frames "
      "(tofnav verify)";
  const Rigid3d world_from_mount = VerifyMount(s, "headframe").motion.start;
  const Eigen::Vector3d centre = head.anatomy.centre_in_image;
  // Out of view behind the wearer, as evd-usecase parks its occluders.
  const Rigid3d parked(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0.0, 2500.0, 2500.0));
  VerifyMount(s, "hand_motion").motion = StaticMotion(parked);

  const Eigen::Vector3d tip_in_tool = InstrumentTipInTool(InstrumentOptions{});
  const Eigen::Vector3d up(0.0, 0.0, 1.0), anterior(0.0, -1.0, 0.0);
  const Eigen::Vector3d facing = (anterior + 0.6 * up).normalized();  // towards the wearer
  const Rigid3d pointer_parked(parked.rotation,
                               parked.translation + Eigen::Vector3d(1000.0, 0.0, 0.0));
  std::vector<Keyframe> keyframes{{0, pointer_parked}};
  std::int64_t slot = kVerifyFirstSlot;
  s.patient->landmarks = VerifyLandmarks(head);
  for (PlannedLandmark& landmark : s.patient->landmarks) {
    const MeshHit hit = head.Probe().RequireHit(landmark.in_image - centre, landmark.name.c_str());
    const Eigen::Vector3d at = landmark.in_image - centre;  // in the mount
    const Eigen::Vector3d rod = hit.normal + kRodUpWeight * up + kRodForwardWeight * anterior;
    const Rigid3d touching = world_from_mount * VerifyPointerPose(at, rod, facing, tip_in_tool);
    const Rigid3d lifted(
        touching.rotation,
        touching.translation + world_from_mount.rotation * (kVerifyLiftMm * hit.normal));
    if (keyframes.size() == 1) {  // in from out of view
      keyframes.push_back({slot - 1, pointer_parked});
      keyframes.push_back({slot, lifted});
    } else {  // over from the last landmark
      keyframes.push_back({slot += kVerifyMoveSlots, lifted});
    }
    keyframes.push_back({slot += kVerifyMoveSlots, touching});
    landmark.touch_first_slot = slot;
    keyframes.push_back({slot += kVerifyRestSlots, touching});
    landmark.touch_last_slot = slot;
    keyframes.push_back({slot += kVerifyMoveSlots, lifted});
  }
  // The wearer watches the pointer's work: the same wander as evd-usecase's, but over a narrower
  // arc and more slowly, so the headframe and the pointer stay in view (a surgeon looks at the
  // landmark being touched).
  HeadWornMotion& wander = s.camera.motion.head_worn;
  wander.azimuth_span_rad = kVerifyAzimuthSpanRad;
  wander.period_s = kVerifyWanderPeriodS;
  VerifyMount(s, "instrument_motion").motion = KeyframeMotion(std::move(keyframes));
  s.frames = slot + kVerifyFirstSlot;
  return s;
}

}  // namespace tofnav::sim
