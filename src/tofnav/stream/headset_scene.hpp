// SPDX-License-Identifier: BSD-3-Clause
// What the headset wearer sees for one NavigationState: spheres, cylinders and a text panel in
// `world` (docs/navigation.md, "Headset display"). Pure; HeadsetDisplay sends it.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "tofnav/imaging/trajectory.hpp"
#include "tofnav/pipeline/navigator.hpp"
#include "tofnav/stream/remote_scene_protocol.hpp"

namespace tofnav {

enum class HologramShape { kSphere, kCylinder, kText };

/// How the instrument lies against the active trajectory (the colour of the active plan and of
/// the instrument).
enum class GuidanceLevel {
  kNoGuidance,  // grey: no instrument, or the instrument is not tracked in this frame
  kOffTarget,   // amber: tip off the planned line or axis off its direction by more than allowed
  kOnTarget,    // green: within both
};

/// One object of the remote scene, in `world` [mm].
struct Hologram {
  HologramShape shape = HologramShape::kSphere;
  bool visible = false;
  /// Sphere: centre a. Cylinder: from a to b. Text: at a, facing a viewer at b.
  Eigen::Vector3d a_in_world = Eigen::Vector3d::Zero();
  Eigen::Vector3d b_in_world = Eigen::Vector3d::Zero();
  double diameter_mm = 0.0;  // spheres and cylinders
  Rgba colour;
  std::string text;  // text panels
};

struct HeadsetSceneOptions {
  double entry_diameter_mm = 5.0;  // entry and target spheres
  double path_diameter_mm = 1.5;
  double path_extension_mm = 30.0;  // the path goes on this far outside the skin (before entry)
  double instrument_diameter_mm = 2.0;
  double instrument_length_mm = 120.0;  // the axis drawn back from the tip
  double tip_diameter_mm = 3.0;
  double on_target_offset_mm = 2.0;        // tip distance from the planned line
  double on_target_angle_rad = 0.0349066;  // 2 deg: instrument axis vs planned direction
  /// The scene is shown only from a reference pose at most this old [s] (the Navigator's
  /// stale_after_s should not exceed it).
  double max_pose_age_s = 0.1;
  bool show_other_trajectories = true;  // dimmed
  double text_offset_mm = 40.0;         // the panel sits this far above the entry
  float font_size = 0.12f;              // TextMeshPro font size (tune on the device)
  Eigen::Vector3d up_in_world = Eigen::Vector3d::UnitY();  // HoloLens world: +y up
  void Check() const;  // throws PreconditionError naming the bad field
};

/// Lines shown above the panel's own (e.g. tofnav verify's prompt), and where the panel goes when
/// the plan has no trajectory: `anchor_in_image` placed by world_from_image.
struct PanelNote {
  std::string text;
  std::optional<Eigen::Vector3d> anchor_in_image;
};

/// The holograms of one frame in fixed slots: per trajectory i, 3i entry sphere, 3i + 1 target
/// sphere, 3i + 2 path cylinder; then the instrument axis, its tip and the text panel.
struct HeadsetScene {
  std::vector<Hologram> holograms;
  bool shown = false;       // placed from a reference pose no older than max_pose_age_s
  double pose_age_s = 0.0;  // the state's reference_age_s when shown
  GuidanceLevel level = GuidanceLevel::kNoGuidance;
  /// The reference is SETTLING (NavigationState::reference_settling): the guidance is drawn grey
  /// and "on target" is not said until its orientation has been averaged.
  bool settling = false;
};

std::size_t HeadsetSlotCount(std::size_t trajectories);
inline std::size_t InstrumentAxisSlot(std::size_t trajectories) { return 3 * trajectories; }
inline std::size_t InstrumentTipSlot(std::size_t trajectories) { return 3 * trajectories + 1; }
inline std::size_t TextPanelSlot(std::size_t trajectories) { return 3 * trajectories + 2; }

/// Whether the scene may be shown from `state`: a world_from_image from the reference tracked
/// (or held) no longer than `max_pose_age_s` ago.
bool HeadsetPoseFresh(const NavigationState& state, double max_pose_age_s);

/// The scene of `state` for `plan` (the NavigationCase's plan, for names and slot count).
/// Everything is invisible when the pose is not fresh.
HeadsetScene ComposeHeadsetScene(const NavigationState& state, const std::vector<Trajectory>& plan,
                                 const HeadsetSceneOptions& options = {},
                                 const PanelNote& note = {});

/// Whether the geometry of `next` differs from `shown`: an end point (or the diameter) moved by
/// more than `min_move_mm`, or the direction a -> b turned by more than `min_turn_rad`.
bool HologramMoved(const Hologram& shown, const Hologram& next, double min_move_mm,
                   double min_turn_rad);
/// Whether `next` must be sent over `shown`: visibility, colour or text differ, or (when visible)
/// an end point moved by more than `min_move_mm` or the direction a -> b turned by more than
/// `min_turn_rad`.
bool HologramChanged(const Hologram& shown, const Hologram& next, double min_move_mm,
                     double min_turn_rad);

/// Where the plugin must put `h`'s primitive (or text) in Unity's world, `up_in_world` keeping a
/// text panel upright.
UnityTransform HologramTransform(const Hologram& h, const Eigen::Vector3d& up_in_world);

}  // namespace tofnav
