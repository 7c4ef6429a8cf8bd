// SPDX-License-Identifier: BSD-3-Clause
// Motions: exact stage and platform kinematics, sequences, head-worn ranges and speeds, look-at.
#include "tofnav/sim/motion.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "matchers.hpp"
#include "tofnav/core/require.hpp"

namespace tofnav::sim {
namespace {

constexpr double kRateHz = 45.0;
constexpr double kExactMm = 1e-9;  // closed-form kinematics: rounding only
constexpr double kExactRad = 1e-9;

Rigid3d Tilted() {
  return {Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized())),
          Eigen::Vector3d(10.0, -20.0, 30.0)};
}

TEST(MotionPose, LinearStageMovesAtConstantSpeedAndStopsAtTheEnd) {
  const Motion motion = LinearStageMotion(Tilted(), {0.0, 0.0, -2.0}, 40.0, 400.0);
  for (const std::int64_t slot : {0, 1, 45, 200, 449}) {
    const Rigid3d pose = MotionPose(motion, slot, kRateHz, 1);
    const double travelled_mm = 40.0 * static_cast<double>(slot) / kRateHz;
    EXPECT_THAT(pose,
                RigidNear(Rigid3d(Tilted().rotation,
                                  Tilted().translation + Eigen::Vector3d(0, 0, -travelled_mm)),
                          kExactRad, kExactMm))
        << slot;
  }
  const Rigid3d end = MotionPose(motion, 10'000, kRateHz, 1);
  EXPECT_NEAR(end.translation.z(), 30.0 - 400.0, kExactMm);
}

TEST(MotionPose, LinearBackAndForthTurnsAtTheEnds) {
  Motion motion = LinearStageMotion(Rigid3d(), Eigen::Vector3d::UnitX(), 45.0, 100.0);
  motion.linear.back_and_forth = true;
  // 45 mm/s at 45 Hz: 1 mm per slot.
  EXPECT_NEAR(MotionPose(motion, 60, kRateHz, 1).translation.x(), 60.0, kExactMm);
  EXPECT_NEAR(MotionPose(motion, 130, kRateHz, 1).translation.x(), 70.0, kExactMm);
  EXPECT_NEAR(MotionPose(motion, 230, kRateHz, 1).translation.x(), 30.0, kExactMm);
}

TEST(MotionPose, RotationPlatformTurnsAboutItsAxisThroughTheCentre) {
  Motion motion;
  motion.kind = MotionKind::kRotation;
  motion.start = Rigid3d(Eigen::Quaterniond::Identity(), {100.0, 5.0, 0.0});
  motion.rotation = {Eigen::Vector3d::UnitY(), {50.0, 0.0, 0.0}, 0.45, 0.1, 0.0};
  for (const std::int64_t slot : {0, 10, 100, 1000}) {
    const double angle = 0.1 + 0.45 * static_cast<double>(slot) / kRateHz;
    const Rigid3d pose = MotionPose(motion, slot, kRateHz, 1);
    const Eigen::Vector3d expected =
        Eigen::Vector3d(50.0, 0.0, 0.0) +
        Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitY()) * Eigen::Vector3d(50.0, 5.0, 0.0);
    EXPECT_NEAR((pose.translation - expected).norm(), 0.0, kExactMm) << slot;
    EXPECT_NEAR(pose.rotation.angularDistance(
                    Eigen::Quaterniond(Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitY()))),
                0.0, kExactRad);
  }
}

TEST(MotionPose, RotationSweepReturnsAtConstantSpeed) {
  Motion motion;
  motion.kind = MotionKind::kRotation;
  motion.rotation = {Eigen::Vector3d::UnitZ(), Eigen::Vector3d::Zero(), 0.45, -0.5, 1.0};
  const auto angle_at = [&](std::int64_t slot) {
    return Eigen::AngleAxisd(MotionPose(motion, slot, kRateHz, 1).rotation).angle() *
           (Eigen::AngleAxisd(MotionPose(motion, slot, kRateHz, 1).rotation).axis().z() < 0 ? -1.0
                                                                                            : 1.0);
  };
  // 0.01 rad per slot: +0.5 rad after 100 slots (after 1 rad of sweep), back to -0.3 at 180.
  EXPECT_NEAR(angle_at(50), 0.0, kExactRad);
  EXPECT_NEAR(angle_at(100), 0.5, kExactRad);
  EXPECT_NEAR(angle_at(180), -0.3, kExactRad);
}

TEST(MotionPose, SequencePlaysSegmentsInOrderEachFromItsOwnTimeZero) {
  Motion first = StaticMotion(Rigid3d(Eigen::Quaterniond::Identity(), {1.0, 0.0, 0.0}));
  first.segment_slots = 10;
  Motion second = LinearStageMotion(Rigid3d(), Eigen::Vector3d::UnitY(), 45.0, 1000.0);
  second.segment_slots = 20;
  const Motion sequence = SequenceMotion({first, second});
  EXPECT_EQ(MotionSlots(sequence), 30);
  EXPECT_NEAR(MotionPose(sequence, 9, kRateHz, 1).translation.x(), 1.0, kExactMm);
  EXPECT_NEAR(MotionPose(sequence, 10, kRateHz, 1).translation.y(), 0.0, kExactMm);
  EXPECT_NEAR(MotionPose(sequence, 15, kRateHz, 1).translation.y(), 5.0, kExactMm);
  EXPECT_NEAR(MotionPose(sequence, 40, kRateHz, 1).translation.y(), 30.0, kExactMm);  // keeps going
}

TEST(LookAt, PointsZAtTheTargetAndYAwayFromUp) {
  const Eigen::Vector3d eye(100.0, 300.0, 500.0), target(0.0, 100.0, 0.0);
  const Rigid3d pose = LookAt(eye, target);
  const Eigen::Matrix3d r = pose.RotationMatrix();
  EXPECT_NEAR((r.col(2) - (target - eye).normalized()).norm(), 0.0, 1e-12);
  EXPECT_LT(r.col(1).dot(Eigen::Vector3d::UnitY()), 0.0);           // image y points down
  EXPECT_NEAR(r.col(0).dot(Eigen::Vector3d::UnitY()), 0.0, 1e-12);  // no roll
  EXPECT_NEAR(r.determinant(), 1.0, 1e-12);
  EXPECT_EQ(pose.translation, eye);
}

struct Samples {
  std::vector<double> range_mm, aim_error_rad, speed_mm_per_s, turn_rad_per_s;
};

Samples SampleHeadWorn(const HeadWornMotion& m, std::uint64_t seed) {
  Motion motion;
  motion.kind = MotionKind::kHeadWorn;
  motion.head_worn = m;
  Samples s;
  Rigid3d previous = MotionPose(motion, 0, kRateHz, seed);
  for (std::int64_t slot = 1; slot < 45 * 60; slot += 3) {  // one minute
    const Rigid3d pose = MotionPose(motion, slot, kRateHz, seed);
    const Eigen::Vector3d to_target = m.target_in_world - pose.translation;
    s.range_mm.push_back(to_target.norm());
    s.aim_error_rad.push_back(std::acos(std::clamp(
        to_target.normalized().dot(pose.rotation * Eigen::Vector3d::UnitZ()), -1.0, 1.0)));
    const Rigid3d step = MotionPose(motion, slot + 1, kRateHz, seed);
    s.speed_mm_per_s.push_back((step.translation - pose.translation).norm() * kRateHz);
    s.turn_rad_per_s.push_back(step.rotation.angularDistance(pose.rotation) * kRateHz);
    previous = pose;
  }
  return s;
}

double Median(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

TEST(MotionPose, HeadWornStaysInItsRangesAtRealisticSpeeds) {
  HeadWornMotion m;
  m.target_in_world = {10.0, 200.0, -5.0};
  const Samples s = SampleHeadWorn(m, 7);
  // The aim point wanders up to aim_radius from the target, so the range may exceed its band by
  // that much; the line of sight misses the target by at most asin(aim_radius / min_range).
  EXPECT_GE(*std::min_element(s.range_mm.begin(), s.range_mm.end()),
            m.min_range_mm - m.aim_radius_mm);
  EXPECT_LE(*std::max_element(s.range_mm.begin(), s.range_mm.end()),
            m.max_range_mm + m.aim_radius_mm);
  EXPECT_LE(*std::max_element(s.aim_error_rad.begin(), s.aim_error_rad.end()),
            std::asin(m.aim_radius_mm / (m.min_range_mm - m.aim_radius_mm)));
  // It uses the range band, not just its middle.
  EXPECT_LT(*std::min_element(s.range_mm.begin(), s.range_mm.end()), 420.0);
  EXPECT_GT(*std::max_element(s.range_mm.begin(), s.range_mm.end()), 580.0);
  // Head motion while looking at something: about 0.05-0.5 m/s and 5-60 deg/s.
  EXPECT_GT(Median(s.speed_mm_per_s), 50.0);
  EXPECT_LT(*std::max_element(s.speed_mm_per_s.begin(), s.speed_mm_per_s.end()), 800.0);
  EXPECT_GT(Median(s.turn_rad_per_s), 0.05);
  EXPECT_LT(*std::max_element(s.turn_rad_per_s.begin(), s.turn_rad_per_s.end()), 1.5);
}

TEST(MotionPose, HeadWornIsReproducibleAndSeeded) {
  Motion motion;
  motion.kind = MotionKind::kHeadWorn;
  const Rigid3d a = MotionPose(motion, 123, kRateHz, 5);
  EXPECT_THAT(MotionPose(motion, 123, kRateHz, 5), RigidNear(a, 0.0, 0.0));
  EXPECT_GT(TranslationDistanceMm(MotionPose(motion, 123, kRateHz, 6), a), 1.0);
}

// The tip (mount origin) never moves; the shaft sweeps a cone of up to tilt_rad about its rest
// axis, covering directions up to ~2 tilt_rad apart within two periods.
TEST(MotionPose, PivotKeepsTheTipAndSweepsTheCone) {
  Motion motion;
  motion.kind = MotionKind::kPivot;
  motion.start = Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitX())),
                         Eigen::Vector3d(10.0, 150.0, -380.0));
  ASSERT_NO_THROW(motion.Check());
  const Eigen::Vector3d rest = motion.start.rotation * Eigen::Vector3d::UnitZ();
  std::vector<Eigen::Vector3d> shafts;
  for (std::int64_t slot = 0; slot < 2 * 4 * 45; ++slot) {
    const Rigid3d pose = MotionPose(motion, slot, kRateHz, 0);
    EXPECT_LT((pose.translation - motion.start.translation).norm(), kExactMm);
    shafts.push_back(pose.rotation * Eigen::Vector3d::UnitZ());
    const double tilt = std::acos(std::clamp(shafts.back().dot(rest), -1.0, 1.0));
    EXPECT_LE(tilt, motion.pivot.tilt_rad + 1e-9);
    EXPECT_GE(tilt, 0.6 * motion.pivot.tilt_rad - 1e-9);
  }
  double widest = 0.0;
  for (const Eigen::Vector3d& a : shafts) {
    for (const Eigen::Vector3d& b : shafts)
      widest = std::max(widest, std::acos(std::min(1.0, a.dot(b))));
  }
  EXPECT_GT(widest, 1.5 * motion.pivot.tilt_rad);
  motion.pivot.tilt_rad = 2.0;
  EXPECT_THROW(motion.Check(), PreconditionError);
}

TEST(MotionPose, KeyframesInterpolateHoldAndNestInSequences) {
  const Rigid3d a(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0.0, 0.0, 100.0));
  const Rigid3d b(Eigen::Quaterniond(Eigen::AngleAxisd(0.8, Eigen::Vector3d::UnitY())),
                  Eigen::Vector3d(40.0, 0.0, 300.0));
  const Motion keyed = KeyframeMotion({{10, a}, {30, b}});
  EXPECT_THAT(MotionPose(keyed, 0, kRateHz, 0), RigidNear(a, 0.0, 0.0));   // held before
  EXPECT_THAT(MotionPose(keyed, 99, kRateHz, 0), RigidNear(b, 0.0, 0.0));  // and after
  const Rigid3d middle(Eigen::Quaterniond(Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitY())),
                       Eigen::Vector3d(20.0, 0.0, 200.0));
  EXPECT_THAT(MotionPose(keyed, 20, kRateHz, 0), RigidNear(middle, 1e-9, 1e-9));
  Motion first = StaticMotion(Rigid3d());
  first.segment_slots = 5;
  const Motion sequence = SequenceMotion({first, keyed});
  EXPECT_THAT(MotionPose(sequence, 25, kRateHz, 0), RigidNear(middle, 1e-9, 1e-9));
  EXPECT_EQ(MotionKeySlots(sequence), (std::vector<std::int64_t>{0, 5, 15, 35}));
  EXPECT_THROW(KeyframeMotion({{3, a}, {3, b}}).Check(), PreconditionError);
  EXPECT_THROW(KeyframeMotion({}).Check(), PreconditionError);
}

TEST(Motion, CheckNamesTheBadField) {
  Motion motion = LinearStageMotion(Rigid3d(), Eigen::Vector3d::Zero(), 1.0, 1.0);
  EXPECT_THROW(motion.Check(), PreconditionError);
  Motion worn;
  worn.kind = MotionKind::kHeadWorn;
  worn.head_worn.min_range_mm = 800.0;
  EXPECT_THROW(worn.Check(), PreconditionError);
  EXPECT_THROW(SequenceMotion({}).Check(), PreconditionError);
}

}  // namespace
}  // namespace tofnav::sim
