// SPDX-License-Identifier: BSD-3-Clause
// Motions: closed-form poses at any frame slot, so frames can be dropped or rendered in any order.
#include "tofnav/sim/motion.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <utility>

#include "tofnav/core/require.hpp"
#include "tofnav/core/units.hpp"
#include "tofnav/sim/random.hpp"

namespace tofnav::sim {
namespace {

// Triangle wave over [0, span]: position after travelling `distance` back and forth.
double PingPong(double distance, double span) {
  if (span <= 0.0) return 0.0;
  const double p = std::fmod(std::max(distance, 0.0), 2.0 * span);
  return p <= span ? p : 2.0 * span - p;
}

// A smooth random signal in [-1, 1]: three seeded sinusoids near 1, 2 and 3.5 cycles per period.
class SmoothChannel {
 public:
  SmoothChannel(std::uint64_t seed, double period_s) {
    static constexpr std::array<double, 3> kAmplitude = {0.6, 0.3, 0.1};
    static constexpr std::array<double, 3> kLowCycles = {0.7, 1.6, 3.0};
    static constexpr std::array<double, 3> kHighCycles = {1.3, 2.4, 4.0};
    std::uint64_t state = seed;
    const auto uniform = [&state] {
      state += 0x9E3779B97F4A7C15ull;
      return static_cast<double>(MixBits(state) >> 11) * 0x1.0p-53;
    };
    for (std::size_t k = 0; k < 3; ++k) {
      const double cycles = kLowCycles[k] + (kHighCycles[k] - kLowCycles[k]) * uniform();
      terms_[k] = {kAmplitude[k], kTwoPi * cycles / period_s, kTwoPi * uniform()};
    }
  }
  double operator()(double t_s) const {
    double value = 0.0;
    for (const Term& term : terms_)
      value += term.amplitude * std::sin(term.omega * t_s + term.phase);
    return value;
  }

 private:
  struct Term {
    double amplitude = 0.0;
    double omega = 0.0;  // [rad/s]
    double phase = 0.0;  // [rad]
  };
  std::array<Term, 3> terms_{};
};

Rigid3d HeadWornPose(const HeadWornMotion& m, double t_s, std::uint64_t seed) {
  const auto channel = [&](std::uint64_t index) {
    return SmoothChannel(StreamSeed(seed, index), m.period_s)(t_s);
  };
  const Eigen::Vector3d up = m.up_in_world.normalized();
  const Eigen::Vector3d toward =
      (m.toward_wearer_in_world - m.toward_wearer_in_world.dot(up) * up).normalized();
  const Eigen::Vector3d side = up.cross(toward);
  const double range_mm = 0.5 * (m.min_range_mm + m.max_range_mm) +
                          0.5 * (m.max_range_mm - m.min_range_mm) * channel(0);
  const double azimuth_rad = 0.5 * m.azimuth_span_rad * channel(1);
  const double elevation_rad = 0.5 * (m.min_elevation_rad + m.max_elevation_rad) +
                               0.5 * (m.max_elevation_rad - m.min_elevation_rad) * channel(2);
  const Eigen::Vector3d aim_in_world =
      m.target_in_world + m.aim_radius_mm / std::sqrt(3.0) *
                              (channel(3) * side + channel(4) * up + channel(5) * toward);
  const double roll_rad = 0.5 * m.roll_span_rad * channel(6);
  const Eigen::Vector3d direction =
      std::cos(elevation_rad) * (std::cos(azimuth_rad) * toward + std::sin(azimuth_rad) * side) +
      std::sin(elevation_rad) * up;
  const Rigid3d world_from_look = LookAt(aim_in_world + range_mm * direction, aim_in_world, up);
  return world_from_look *
         Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(roll_rad, Eigen::Vector3d::UnitZ())),
                 Eigen::Vector3d::Zero());
}

// Closed form of PivotMotion (motion.hpp): rotations about the mount origin, the tip.
Rigid3d PivotPose(const Rigid3d& start, const PivotMotion& m, double t_s) {
  const double phase = kTwoPi * t_s / m.period_s;
  const double tilt_rad = m.tilt_rad * (0.8 + 0.2 * std::sin(phase / 2.7));
  const Eigen::Vector3d tilt_axis(std::cos(phase), std::sin(phase), 0.0);
  const Eigen::Quaterniond swing =
      Eigen::AngleAxisd(tilt_rad, tilt_axis) *
      Eigen::AngleAxisd(m.spin_rad * std::sin(phase / 1.7), Eigen::Vector3d::UnitZ());
  return start * Rigid3d(swing, Eigen::Vector3d::Zero());
}

// Linear translation and slerp between the keyframes around `slot`; held before and after.
Rigid3d KeyframePose(const std::vector<Keyframe>& keyframes, std::int64_t slot) {
  Require(!keyframes.empty(), "MotionPose: no keyframes");
  if (slot <= keyframes.front().slot) return keyframes.front().pose;
  if (slot >= keyframes.back().slot) return keyframes.back().pose;
  const auto next = std::upper_bound(keyframes.begin(), keyframes.end(), slot,
                                     [](std::int64_t s, const Keyframe& k) { return s < k.slot; });
  const Keyframe& b = *next;
  const Keyframe& a = *(next - 1);
  const double f = static_cast<double>(slot - a.slot) / static_cast<double>(b.slot - a.slot);
  return {a.pose.rotation.slerp(f, b.pose.rotation),
          (1.0 - f) * a.pose.translation + f * b.pose.translation};
}

}  // namespace

void Motion::Check() const {
  Require(start.translation.allFinite() && start.rotation.coeffs().allFinite(),
          "Motion.start must be finite");
  Require(segment_slots >= 1, "Motion.segment_slots must be >= 1");
  switch (kind) {
    case MotionKind::kStatic:
      break;
    case MotionKind::kLinear:
      Require(linear.direction_in_world.norm() > 1e-9, "Motion.linear.direction must be non-zero");
      Require(std::isfinite(linear.speed_mm_per_s) && linear.speed_mm_per_s >= 0.0,
              "Motion.linear.speed_mm_per_s must be >= 0");
      Require(std::isfinite(linear.travel_mm) && linear.travel_mm >= 0.0,
              "Motion.linear.travel_mm must be >= 0");
      break;
    case MotionKind::kRotation:
      Require(rotation.axis_in_world.norm() > 1e-9, "Motion.rotation.axis must be non-zero");
      Require(std::isfinite(rotation.speed_rad_per_s) && std::isfinite(rotation.start_angle_rad) &&
                  rotation.centre_in_world.allFinite(),
              "Motion.rotation: values must be finite");
      Require(std::isfinite(rotation.sweep_rad) && rotation.sweep_rad >= 0.0,
              "Motion.rotation.sweep_rad must be >= 0");
      break;
    case MotionKind::kHeadWorn: {
      const HeadWornMotion& h = head_worn;
      Require(h.up_in_world.norm() > 1e-9, "Motion.head_worn.up must be non-zero");
      const Eigen::Vector3d up = h.up_in_world.normalized();
      Require((h.toward_wearer_in_world - h.toward_wearer_in_world.dot(up) * up).norm() > 1e-6,
              "Motion.head_worn.toward_wearer must not be parallel to up");
      Require(h.min_range_mm > 0.0 && h.max_range_mm >= h.min_range_mm,
              "Motion.head_worn: need 0 < min_range_mm <= max_range_mm");
      Require(h.min_elevation_rad > -0.5 * std::numbers::pi &&
                  h.max_elevation_rad < 0.5 * std::numbers::pi &&
                  h.min_elevation_rad <= h.max_elevation_rad,
              "Motion.head_worn: need -pi/2 < min_elevation_rad <= max_elevation_rad < pi/2");
      Require(h.azimuth_span_rad >= 0.0 && h.aim_radius_mm >= 0.0 && h.roll_span_rad >= 0.0,
              "Motion.head_worn: spans and aim radius must be >= 0");
      Require(h.period_s > 0.0, "Motion.head_worn.period_s must be > 0");
      Require(h.target_in_world.allFinite(), "Motion.head_worn.target must be finite");
      break;
    }
    case MotionKind::kPivot:
      Require(std::isfinite(pivot.tilt_rad) && pivot.tilt_rad >= 0.0 &&
                  pivot.tilt_rad < 0.5 * std::numbers::pi,
              "Motion.pivot.tilt_rad must be in [0, pi/2)");
      Require(std::isfinite(pivot.period_s) && pivot.period_s > 0.0,
              "Motion.pivot.period_s must be > 0");
      Require(std::isfinite(pivot.spin_rad) && pivot.spin_rad >= 0.0,
              "Motion.pivot.spin_rad must be >= 0");
      break;
    case MotionKind::kSequence:
      Require(!segments.empty(), "Motion: a sequence needs at least one segment");
      for (const Motion& segment : segments) segment.Check();
      break;
    case MotionKind::kKeyframes:
      Require(!keyframes.empty(), "Motion: keyframes need at least one keyframe");
      for (std::size_t i = 0; i < keyframes.size(); ++i) {
        const Keyframe& k = keyframes[i];
        Require(k.slot >= 0, "Motion.keyframes: slots must be >= 0");
        Require(i == 0 || k.slot > keyframes[i - 1].slot,
                "Motion.keyframes: slots must be strictly increasing");
        Require(k.pose.translation.allFinite() && k.pose.rotation.coeffs().allFinite(),
                "Motion.keyframes: poses must be finite");
      }
      break;
  }
}

Motion StaticMotion(const Rigid3d& world_from_mount) {
  Motion motion;
  motion.start = world_from_mount;
  return motion;
}

Motion LinearStageMotion(const Rigid3d& start, const Eigen::Vector3d& direction_in_world,
                         double speed_mm_per_s, double travel_mm) {
  Motion motion;
  motion.kind = MotionKind::kLinear;
  motion.start = start;
  motion.linear = {direction_in_world, speed_mm_per_s, travel_mm, false};
  return motion;
}

Motion SequenceMotion(std::vector<Motion> segments) {
  Motion motion;
  motion.kind = MotionKind::kSequence;
  motion.segments = std::move(segments);
  return motion;
}

Motion KeyframeMotion(std::vector<Keyframe> keyframes) {
  Motion motion;
  motion.kind = MotionKind::kKeyframes;
  motion.keyframes = std::move(keyframes);
  return motion;
}

Rigid3d MotionPose(const Motion& motion, std::int64_t slot, double rate_hz, std::uint64_t seed) {
  Require(rate_hz > 0.0, "MotionPose: rate_hz must be > 0");
  const double t_s = static_cast<double>(slot) / rate_hz;
  switch (motion.kind) {
    case MotionKind::kStatic:
      return motion.start;
    case MotionKind::kLinear: {
      const LinearMotion& m = motion.linear;
      const double travelled_mm = m.speed_mm_per_s * t_s;
      const double s_mm = m.back_and_forth ? PingPong(travelled_mm, m.travel_mm)
                                           : std::clamp(travelled_mm, 0.0, m.travel_mm);
      return {motion.start.rotation,
              motion.start.translation + s_mm * m.direction_in_world.normalized()};
    }
    case MotionKind::kRotation: {
      const RotationMotion& m = motion.rotation;
      const double turned_rad = m.speed_rad_per_s * t_s;
      const double angle_rad =
          m.start_angle_rad + (m.sweep_rad > 0.0 ? PingPong(turned_rad, m.sweep_rad) : turned_rad);
      const Eigen::Quaterniond turn(Eigen::AngleAxisd(angle_rad, m.axis_in_world.normalized()));
      return {turn * motion.start.rotation,
              m.centre_in_world + turn * (motion.start.translation - m.centre_in_world)};
    }
    case MotionKind::kHeadWorn:
      return HeadWornPose(motion.head_worn, t_s, seed);
    case MotionKind::kPivot:
      return PivotPose(motion.start, motion.pivot, t_s);
    case MotionKind::kSequence: {
      std::int64_t begin = 0;
      for (std::size_t i = 0; i < motion.segments.size(); ++i) {
        const Motion& segment = motion.segments[i];
        const bool last = i + 1 == motion.segments.size();
        if (last || slot < begin + segment.segment_slots) {
          return MotionPose(segment, slot - begin, rate_hz, StreamSeed(seed, i));
        }
        begin += segment.segment_slots;
      }
      break;
    }
    case MotionKind::kKeyframes:
      return KeyframePose(motion.keyframes, slot);
  }
  Require(false, "MotionPose: empty sequence");
  return {};
}

std::vector<std::int64_t> MotionKeySlots(const Motion& motion) {
  std::vector<std::int64_t> slots = {0};
  if (motion.kind == MotionKind::kKeyframes) {
    for (const Keyframe& k : motion.keyframes) slots.push_back(k.slot);
  } else if (motion.kind == MotionKind::kSequence) {
    std::int64_t begin = 0;
    for (const Motion& segment : motion.segments) {
      for (const std::int64_t s : MotionKeySlots(segment)) slots.push_back(begin + s);
      begin += segment.segment_slots;
    }
  }
  std::sort(slots.begin(), slots.end());
  slots.erase(std::unique(slots.begin(), slots.end()), slots.end());
  return slots;
}

std::int64_t MotionSlots(const Motion& motion) {
  if (motion.kind != MotionKind::kSequence) return 0;
  std::int64_t slots = 0;
  for (const Motion& segment : motion.segments) slots += segment.segment_slots;
  return slots;
}

Rigid3d LookAt(const Eigen::Vector3d& eye_in_world, const Eigen::Vector3d& target_in_world,
               const Eigen::Vector3d& up_in_world) {
  const Eigen::Vector3d z = (target_in_world - eye_in_world).normalized();
  Require(z.allFinite(), "LookAt: eye and target coincide");
  Eigen::Vector3d down = -up_in_world.normalized();
  if (std::abs(down.dot(z)) > 0.999) down = z.unitOrthogonal();  // looking straight up or down
  const Eigen::Vector3d x = down.cross(z).normalized();
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Matrix3d rotation;
  rotation << x, y, z;
  return {Eigen::Quaterniond(rotation), eye_in_world};
}

}  // namespace tofnav::sim
