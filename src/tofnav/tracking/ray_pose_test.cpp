// SPDX-License-Identifier: BSD-3-Clause
// PnP on rays: exact recovery from a perturbed start, blind to range errors.
#include "tofnav/tracking/ray_pose.hpp"

#include <gtest/gtest.h>

#include <random>

#include "matchers.hpp"
#include "tofnav/core/rigid_fit.hpp"
#include "tofnav/core/rotation_vector.hpp"
#include "tracking_test_tools.hpp"

namespace tofnav {
namespace {

TEST(EstimatePoseFromRays, RecoversThePoseFromRaysAloneDespiteBiasedStartingCentres) {
  constexpr double kRotTolRad = 1e-6, kTransTolMm = 1e-4;  // converged iteration
  const Points3d markers = {{-60, -40, 0}, {0, -45, 0}, {55, -35, 0}, {-50, 40, 0},
                            {5, 35, 0},    {60, 45, 0}, {10, 0, 0}};  // a planar structure
  const Rigid3d truth = testing::FacingToolPose({15.0, -20.0, 520.0}, 0.25, 0.4);
  Points3d rays, biased;
  for (const Eigen::Vector3d& m : markers) {
    const Eigen::Vector3d c = truth * m;
    rays.push_back(c.normalized());
    biased.push_back(c.normalized() * (c.norm() + 3.0));  // a 3 mm range error on every marker
  }
  Rigid3d start = testing::FacingToolPose({15.0, -20.0, 523.0}, 0.2, 0.45);
  const RayPoseResult r = EstimatePoseFromRays(markers, rays, start);
  ASSERT_TRUE(r.converged);
  EXPECT_THAT(r.ahat_from_tool, RigidNear(truth, kRotTolRad, kTransTolMm));
  EXPECT_LT(r.rms_ray_distance_mm, 1e-6);
  EXPECT_THROW(EstimatePoseFromRays(Points3d(2), Points3d(2), start), std::invalid_argument);
}

TEST(EstimatePoseFromRaysAndRanges, TrustsRaysOverNoisyRangesAndMatchesExactData) {
  constexpr double kRotTolRad = 1e-6, kTransTolMm = 1e-4;  // converged iteration, exact data
  // Small flat tool (35 mm lever arm) at 500 mm: the Kabsch tilt error of this range noise.
  constexpr double kKabschTiltRad = 0.01;
  const Points3d markers = {{-35, 0, 0}, {35, 0, 0}, {0, -35, 0}, {0, 35, 0}};
  const Rigid3d truth = testing::FacingToolPose({10.0, 5.0, 500.0}, 0.3, 0.2);
  const double range_noise_mm[] = {1.0, -1.0, -1.0, 1.0};  // tilts an isotropic fit
  std::vector<RayRangeObservation> exact, noisy;
  Points3d noisy_centres;
  for (std::size_t i = 0; i < markers.size(); ++i) {
    const Eigen::Vector3d c = truth * markers[i];
    exact.push_back({c.normalized(), c.norm(), 0.01, 1.0});
    noisy.push_back({c.normalized(), c.norm() + range_noise_mm[i], 0.01, 1.0});
    noisy_centres.push_back(noisy.back().ray_in_ahat * noisy.back().range_mm);
  }
  const Rigid3d start = testing::FacingToolPose({12.0, 4.0, 503.0}, 0.25, 0.25);
  const RayPoseResult r = EstimatePoseFromRaysAndRanges(markers, exact, start);
  ASSERT_TRUE(r.converged);
  EXPECT_THAT(r.ahat_from_tool, RigidNear(truth, kRotTolRad, kTransTolMm));
  const Rigid3d kabsch = FitRigid(markers, noisy_centres).target_from_source;
  const RayPoseResult n = EstimatePoseFromRaysAndRanges(markers, noisy, kabsch);
  ASSERT_TRUE(n.converged);
  EXPECT_GT(RotationDistanceRad(kabsch, truth), kKabschTiltRad);
  EXPECT_LT(RotationDistanceRad(n.ahat_from_tool, truth), 0.5 * RotationDistanceRad(kabsch, truth));
  noisy[0].range_sigma_mm = 0.0;
  EXPECT_THROW(EstimatePoseFromRaysAndRanges(markers, noisy, start), std::invalid_argument);
}

TEST(RayRangePoseCovariance, PredictsTheScatterOfFitsToNoisyMarkers) {
  // 3000 fits: a variance estimated from n samples has a relative sd of sqrt(2 / n) = 2.6 %;
  // 12 % is 4.6 of those, and the linearisation is exact to well under that at 0.5 mm of noise.
  constexpr int kFits = 3000;
  constexpr double kRelTol = 0.12;
  const Points3d markers = {{-35, 0, 0}, {35, 0, 0}, {0, -35, 0}, {0, 50, 0}};
  const Rigid3d truth = testing::FacingToolPose({40.0, -30.0, 600.0}, 0.6, 0.3);  // oblique
  std::vector<RayRangeObservation> exact;
  for (const Eigen::Vector3d& m : markers) {
    const Eigen::Vector3d c = truth * m;
    exact.push_back({c.normalized(), c.norm(), 0.15, 0.6});
  }
  const Eigen::Matrix<double, 6, 6> covariance = RayRangePoseCovariance(markers, exact, truth);
  std::mt19937_64 rng(7);
  std::normal_distribution<double> normal(0.0, 1.0);
  Eigen::Matrix<double, 6, 6> scatter = Eigen::Matrix<double, 6, 6>::Zero();
  for (int f = 0; f < kFits; ++f) {
    std::vector<RayRangeObservation> noisy = exact;
    for (RayRangeObservation& o : noisy) {
      const Eigen::Vector3d c = o.ray_in_ahat * o.range_mm;
      Eigen::Vector3d lateral = Eigen::Vector3d(normal(rng), normal(rng), normal(rng)) * 0.15;
      lateral -= o.ray_in_ahat * o.ray_in_ahat.dot(lateral);
      const Eigen::Vector3d moved = c + lateral;
      o.ray_in_ahat = moved.normalized();
      o.range_mm = moved.norm() + 0.6 * normal(rng);
    }
    const RayPoseResult r = EstimatePoseFromRaysAndRanges(markers, noisy, truth);
    ASSERT_TRUE(r.converged);
    Eigen::Matrix<double, 6, 1> e;
    e.head<3>() = RotationVector(r.ahat_from_tool.rotation * truth.rotation.inverse());
    e.tail<3>() = r.ahat_from_tool.translation - truth.translation;
    scatter += e * e.transpose() / kFits;
  }
  const double predicted_rotation = covariance.topLeftCorner<3, 3>().trace();
  const double predicted_position = covariance.bottomRightCorner<3, 3>().trace();
  const double measured_rotation = scatter.topLeftCorner<3, 3>().trace();
  const double measured_position = scatter.bottomRightCorner<3, 3>().trace();
  EXPECT_NEAR(measured_rotation / predicted_rotation, 1.0, kRelTol);
  EXPECT_NEAR(measured_position / predicted_position, 1.0, kRelTol);
  // Oblique and far, the tool's tilt is several times less certain than its roll about the view.
  const Eigen::Vector3d view = truth.translation.normalized();
  const double roll_var = view.dot(covariance.topLeftCorner<3, 3>() * view);
  EXPECT_GT(predicted_rotation - roll_var, 4.0 * roll_var);
}

}  // namespace
}  // namespace tofnav
