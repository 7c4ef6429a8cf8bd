// SPDX-License-Identifier: BSD-3-Clause
// ComposeHeadsetScene: the plan, the instrument and a text panel from one NavigationState
// (docs/navigation.md, "Headset display").
#include "tofnav/stream/headset_scene.hpp"

#include <cmath>
#include <cstdio>
#include <numbers>

#include "tofnav/core/require.hpp"
#include "tofnav/core/units.hpp"
#include "tofnav/pipeline/guidance.hpp"

namespace tofnav {
namespace {

constexpr Rgba kGrey{0.6f, 0.6f, 0.6f, 1.0f};
constexpr Rgba kAmber{1.0f, 0.65f, 0.0f, 1.0f};
constexpr Rgba kGreen{0.15f, 0.9f, 0.25f, 1.0f};
constexpr Rgba kDimmed{0.45f, 0.55f, 0.8f, 0.35f};
constexpr Rgba kWhite{1.0f, 1.0f, 1.0f, 1.0f};

Rgba LevelColour(GuidanceLevel level) {
  switch (level) {
    case GuidanceLevel::kNoGuidance:
      return kGrey;
    case GuidanceLevel::kOffTarget:
      return kAmber;
    case GuidanceLevel::kOnTarget:
      return kGreen;
  }
  return kGrey;
}

Hologram Sphere(const Eigen::Vector3d& centre, double diameter_mm, const Rgba& colour) {
  return {HologramShape::kSphere, true, centre, centre, diameter_mm, colour, {}};
}

Hologram Cylinder(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double diameter_mm,
                  const Rgba& colour) {
  return {HologramShape::kCylinder, true, a, b, diameter_mm, colour, {}};
}

GuidanceLevel LevelOf(const NavigationState& state, const HeadsetSceneOptions& o) {
  if (!state.guidance || !state.tip_in_world || !state.instrument_axis_in_world) {
    return GuidanceLevel::kNoGuidance;
  }
  const bool on = state.guidance->lateral_offset_mm <= o.on_target_offset_mm &&
                  state.guidance->angle_to_axis_rad <= o.on_target_angle_rad;
  return on ? GuidanceLevel::kOnTarget : GuidanceLevel::kOffTarget;
}

std::string PanelText(const NavigationState& state, const std::vector<Trajectory>& plan) {
  const auto active = static_cast<std::size_t>(state.active_trajectory);
  std::string text = active < plan.size() ? plan[active].name : std::string();
  if (state.low_rate) {  // the camera throttled (no hand in view): poses are up to 200 ms apart
    char rate[64];
    std::snprintf(rate, sizeof rate, "LOW RATE %.0f Hz\n", state.received_rate_hz);
    text = rate + text;
  }
  if (state.reference_settling && state.reference_rotation_sd_rad) {
    // The reference's orientation is one frame's fit, not yet averaged (a plate's first second).
    char settling[64];
    std::snprintf(settling, sizeof settling, "SETTLING %.1f deg\n",
                  *state.reference_rotation_sd_rad * kRadToDeg);
    text = settling + text;
  }
  // The liveness tick: the frame's time in quarter seconds, so the panel changes 4 times a second
  // while fresh poses arrive and a frozen scene is seen to be frozen (docs/navigation.md 6.3).
  char live[48];
  std::snprintf(live, sizeof live, "live %.2f s", std::floor(4.0 * state.timestamp_s) / 4.0);
  text += (text.empty() ? "" : "\n") + std::string(live);
  if (!state.guidance) return plan.empty() ? text : text + "\ninstrument not tracked";
  char line[160];
  std::snprintf(line, sizeof line, "\ntip-entry %.1f mm\nangle %.1f deg\ndepth %.1f mm",
                state.guidance->tip_to_entry_mm, state.guidance->angle_to_axis_rad * kRadToDeg,
                state.guidance->remaining_depth_mm);
  return text + line;
}

}  // namespace

void HeadsetSceneOptions::Check() const {
  Require(entry_diameter_mm > 0.0 && path_diameter_mm > 0.0 && instrument_diameter_mm > 0.0 &&
              tip_diameter_mm > 0.0,
          "HeadsetSceneOptions: diameters must be > 0");
  Require(path_extension_mm >= 0.0, "HeadsetSceneOptions.path_extension_mm must be >= 0");
  Require(instrument_length_mm > 0.0, "HeadsetSceneOptions.instrument_length_mm must be > 0");
  Require(on_target_offset_mm >= 0.0 && on_target_angle_rad >= 0.0,
          "HeadsetSceneOptions: on-target limits must be >= 0");
  Require(std::isfinite(max_pose_age_s) && max_pose_age_s > 0.0,
          "HeadsetSceneOptions.max_pose_age_s must be > 0");
  Require(std::isfinite(font_size) && font_size > 0.0f,
          "HeadsetSceneOptions.font_size must be > 0");
  Require(up_in_world.norm() > 0.0, "HeadsetSceneOptions.up_in_world must be non-zero");
}

std::size_t HeadsetSlotCount(std::size_t trajectories) { return 3 * trajectories + 3; }

bool HeadsetPoseFresh(const NavigationState& state, double max_pose_age_s) {
  const bool placed =
      state.status == NavigationStatus::kTracking || state.status == NavigationStatus::kHolding;
  return placed && state.world_from_image.has_value() && state.reference_age_s <= max_pose_age_s;
}

HeadsetScene ComposeHeadsetScene(const NavigationState& state, const std::vector<Trajectory>& plan,
                                 const HeadsetSceneOptions& options, const PanelNote& note) {
  options.Check();
  const std::size_t n = plan.size();
  HeadsetScene scene;
  scene.holograms.resize(HeadsetSlotCount(n));
  for (std::size_t i = 0; i < n; ++i) {
    scene.holograms[3 * i + 2].shape = HologramShape::kCylinder;
  }
  scene.holograms[InstrumentAxisSlot(n)].shape = HologramShape::kCylinder;
  scene.holograms[TextPanelSlot(n)].shape = HologramShape::kText;
  scene.level = LevelOf(state, options);
  scene.settling = state.reference_settling;
  scene.shown = HeadsetPoseFresh(state, options.max_pose_age_s) && state.plan.size() == n;
  if (!scene.shown) return scene;
  scene.pose_age_s = state.reference_age_s;

  const auto active = static_cast<std::size_t>(state.active_trajectory);
  // While the reference settles, no green: on-target is not claimed on an unaveraged pose.
  const Rgba level_colour = scene.settling ? kGrey : LevelColour(scene.level);
  for (std::size_t i = 0; i < n; ++i) {
    if (i != active && !options.show_other_trajectories) continue;
    const PlacedTrajectory& t = state.plan[i];
    const Rgba colour = i == active ? level_colour : kDimmed;
    const Eigen::Vector3d outward = (t.entry_in_world - t.target_in_world).normalized();
    scene.holograms[3 * i] = Sphere(t.entry_in_world, options.entry_diameter_mm, colour);
    scene.holograms[3 * i + 1] = Sphere(t.target_in_world, options.entry_diameter_mm, colour);
    scene.holograms[3 * i + 2] =
        Cylinder(t.target_in_world, t.entry_in_world + options.path_extension_mm * outward,
                 options.path_diameter_mm, colour);
  }
  if (scene.level != GuidanceLevel::kNoGuidance) {
    const Eigen::Vector3d tip = *state.tip_in_world;
    const Eigen::Vector3d back = -state.instrument_axis_in_world->normalized();
    scene.holograms[InstrumentAxisSlot(n)] =
        Cylinder(tip + options.instrument_length_mm * back, tip, options.instrument_diameter_mm,
                 level_colour);
    scene.holograms[InstrumentTipSlot(n)] = Sphere(tip, options.tip_diameter_mm, level_colour);
  }
  const Eigen::Vector3d up = options.up_in_world.normalized();
  std::optional<Eigen::Vector3d> at;
  if (active < n) {
    at = state.plan[active].entry_in_world + options.text_offset_mm * up;
  } else if (note.anchor_in_image) {
    at = *state.world_from_image * *note.anchor_in_image + options.text_offset_mm * up;
  }
  if (at) {
    // Facing the wearer: the head pose of this frame, else from straight ahead of the panel.
    const Eigen::Vector3d viewer = state.world_from_rig
                                       ? state.world_from_rig->translation
                                       : Eigen::Vector3d(*at + 500.0 * Eigen::Vector3d::UnitZ());
    const std::string text = PanelText(state, plan);
    Hologram& panel = scene.holograms[TextPanelSlot(n)];
    panel = {HologramShape::kText,
             true,
             *at,
             viewer,
             0.0,
             kWhite,
             note.text.empty() ? text : note.text + "\n" + text};
  }
  return scene;
}

bool HologramMoved(const Hologram& shown, const Hologram& next, double min_move_mm,
                   double min_turn_rad) {
  if (std::abs(shown.diameter_mm - next.diameter_mm) > min_move_mm) return true;
  if ((shown.a_in_world - next.a_in_world).norm() > min_move_mm) return true;
  if (next.shape == HologramShape::kSphere) return false;
  if (next.shape == HologramShape::kCylinder &&
      (shown.b_in_world - next.b_in_world).norm() > min_move_mm) {
    return true;
  }
  return AngleBetweenRad(shown.b_in_world - shown.a_in_world, next.b_in_world - next.a_in_world) >
         min_turn_rad;
}

bool HologramChanged(const Hologram& shown, const Hologram& next, double min_move_mm,
                     double min_turn_rad) {
  if (shown.visible != next.visible || !(shown.colour == next.colour) || shown.text != next.text ||
      shown.shape != next.shape) {
    return true;
  }
  return next.visible && HologramMoved(shown, next, min_move_mm, min_turn_rad);
}

UnityTransform HologramTransform(const Hologram& h, const Eigen::Vector3d& up_in_world) {
  switch (h.shape) {
    case HologramShape::kSphere:
      return UnitySphere(h.a_in_world, h.diameter_mm);
    case HologramShape::kCylinder:
      return UnityCylinder(h.a_in_world, h.b_in_world, h.diameter_mm);
    case HologramShape::kText:
      return UnityTextPanel(h.a_in_world, h.b_in_world, up_in_world);
  }
  return {};
}

}  // namespace tofnav
