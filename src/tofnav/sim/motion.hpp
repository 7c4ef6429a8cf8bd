// SPDX-License-Identifier: BSD-3-Clause
// Motions of simulator frames over time: static, linear stage, rotation platform, head-worn, and
// sequences of these.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "tofnav/core/rigid3d.hpp"

namespace tofnav::sim {

enum class MotionKind {
  kStatic,     // world_from_mount = start
  kLinear,     // a linear stage: start translated along a direction at constant speed
  kRotation,   // a rotation platform: start turned about an axis at constant angular speed
  kHeadWorn,   // an HMD wearer wandering around a target, looking at it
  kSequence,   // segments one after the other, each for a number of frame slots
  kPivot,      // an instrument swung about its tip resting in a divot (pivot calibration)
  kKeyframes,  // poses at given slots, interpolated (linear translation, slerp rotation)
};

/// Constant-speed travel along `direction_in_world` from the start pose.
struct LinearMotion {
  Eigen::Vector3d direction_in_world = Eigen::Vector3d::UnitZ();  // normalised on use
  double speed_mm_per_s = 20.0;
  double travel_mm = 400.0;     // stops at the end (or turns back)
  bool back_and_forth = false;  // ping-pong over [0, travel_mm] instead of stopping
};

/// Constant angular speed about an axis through `centre_in_world`.
struct RotationMotion {
  Eigen::Vector3d axis_in_world = Eigen::Vector3d::UnitY();  // normalised on use
  Eigen::Vector3d centre_in_world = Eigen::Vector3d::Zero();
  double speed_rad_per_s = 0.2;
  double start_angle_rad = 0.0;  // angle at t = 0, applied to the start pose
  /// 0: turns for ever. > 0: sweeps start .. start + sweep and back at constant speed.
  double sweep_rad = 0.0;
};

/// The camera of a head-mounted display worn by someone who walks and looks around a target.
/// Each channel (range, azimuth, elevation, aim point, roll) is a smooth random signal: a sum of
/// three sinusoids with seeded frequencies near 1, 2 and 3.5 cycles per `period_s` and phases.
/// The pose is of the frame that looks: +z at the aim point, -y towards up (the `ahat` frame).
struct HeadWornMotion {
  Eigen::Vector3d target_in_world = Eigen::Vector3d::Zero();
  Eigen::Vector3d up_in_world = Eigen::Vector3d::UnitY();
  /// Horizontal direction from the target to the wearer's mean position (azimuth 0).
  Eigen::Vector3d toward_wearer_in_world = Eigen::Vector3d::UnitZ();
  double min_range_mm = 300.0;  // distance from the camera to the aim point
  double max_range_mm = 700.0;
  double azimuth_span_rad = 1.4;   // total, centred on toward_wearer
  double min_elevation_rad = 0.1;  // camera height above the target's horizontal plane, as angle
  double max_elevation_rad = 0.8;
  double aim_radius_mm = 30.0;  // the aim point wanders this far from the target
  double roll_span_rad = 0.25;  // total head roll about the line of sight
  /// Dominant period of the wander [s]: 8 s gives about 0.1-0.3 m/s and 10-30 deg/s.
  double period_s = 8.0;
};

/// An instrument whose tip rests in a divot while the hand swings it about the tip: the mount's
/// origin is the tip (fixed at start.translation) and its +z the shaft (start's +z at rest). The
/// shaft circles the rest axis once per `period_s`, tilted by a tilt that breathes between 60 %
/// and 100 % of `tilt_rad` (so the whole cone is covered), and twists about itself by up to
/// `spin_rad`. The shaft directions of two poses lie up to 2 tilt_rad apart.
struct PivotMotion {
  double tilt_rad = 0.45;  // 26 deg: directions up to 52 deg apart
  double period_s = 4.0;
  double spin_rad = 0.3;
};

/// A pose of a keyframed motion at frame slot `slot` (counted from the motion's own start).
struct Keyframe {
  std::int64_t slot = 0;
  Rigid3d pose;  // world_from_mount
};

/// A frame's motion. The pose it gives is world_from_mount (for a camera: world_from_ahat).
struct Motion {
  MotionKind kind = MotionKind::kStatic;
  Rigid3d start;  // world_from_mount at t = 0 (static, linear, rotation)
  LinearMotion linear;
  RotationMotion rotation;
  HeadWornMotion head_worn;
  PivotMotion pivot;
  /// kSequence: played in order; each segment's own time starts at 0 when it begins. After the
  /// last segment the last one keeps running.
  std::vector<Motion> segments;
  /// kKeyframes: slots strictly increasing. Before the first keyframe the motion holds its pose,
  /// after the last it holds the last; two keyframes one slot apart make a jump (e.g. from a
  /// parking pose out of view to where an occluder enters).
  std::vector<Keyframe> keyframes;
  /// Length of this motion when it is a segment of a sequence [frame slots].
  std::int64_t segment_slots = 1;
  /// Throws PreconditionError naming the bad field.
  void Check() const;
};

/// Convenience constructors.
Motion StaticMotion(const Rigid3d& world_from_mount);
Motion LinearStageMotion(const Rigid3d& start, const Eigen::Vector3d& direction_in_world,
                         double speed_mm_per_s, double travel_mm);
Motion SequenceMotion(std::vector<Motion> segments);
Motion KeyframeMotion(std::vector<Keyframe> keyframes);

/// Pose of the moving frame at frame slot `slot` (time slot / rate_hz). `seed` drives the
/// head-worn wander (and is passed on to segments); the same inputs give the same pose.
Rigid3d MotionPose(const Motion& motion, std::int64_t slot, double rate_hz, std::uint64_t seed);

/// Slots at which the motion changes course, from its own start: 0, the start of every sequence
/// segment and every keyframe (sorted, unique). The places to check a scene's geometry.
std::vector<std::int64_t> MotionKeySlots(const Motion& motion);

/// Frame slots a sequence lasts (sum of its segments); 0 for other kinds (no natural end).
std::int64_t MotionSlots(const Motion& motion);

/// A frame whose +z points from `eye` to `target` and whose -y leans towards `up` (camera look-at:
/// the `ahat` convention x right, y down, z forward).
Rigid3d LookAt(const Eigen::Vector3d& eye_in_world, const Eigen::Vector3d& target_in_world,
               const Eigen::Vector3d& up_in_world = Eigen::Vector3d::UnitY());

}  // namespace tofnav::sim
