// SPDX-License-Identifier: BSD-3-Clause
// The reconstruction pipeline's parts: automatic ROI, options, error statistics, evaluation.
#include "tofnav/pipeline/reconstruct.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "tofnav/core/require.hpp"
#include "tofnav/evaluation/reconstruct_evaluate.hpp"
#include "tofnav/fusion/fusion_test_scenes.hpp"
#include "tofnav/fusion/marching_cubes.hpp"
#include "tofnav/fusion/surface_distance.hpp"
#include "tofnav/fusion/tsdf_volume.hpp"

namespace tofnav {
namespace {

// A 128 px camera sees about 4.7 mm per pixel at 300 mm: the sampled rim of a sphere lies
// within one pixel footprint of the analytic one.
constexpr double kPixelFootprintMm = 5.0;
constexpr double kExactTolMm = 1e-9;

TEST(AutomaticRoi, BoundsTheSeenSphereCapPlusMargin) {
  const AhatCamera camera(SmallFisheyeCalibration(128));
  const Rigid3d tool_from_ahat(Eigen::Quaterniond::Identity(), Eigen::Vector3d(10, 20, 30));
  const Eigen::Vector3d centre_in_tool(10, 20, 330);  // 300 mm straight ahead
  constexpr double kRadiusMm = 50.0;
  const Image<float> range = RenderSphere(camera, tool_from_ahat, centre_in_tool, kRadiusMm);
  AutoRoiOptions options;
  options.centre_window_px = 8;
  options.margin_mm = 30.0;
  const RoiView view{&range, tool_from_ahat};
  const std::optional<Eigen::AlignedBox3d> roi = AutomaticRoi({&view, 1}, camera, options);
  ASSERT_TRUE(roi.has_value());
  // Tangent circle of the cap: radius R sqrt(1 - (R/D)^2), at D - R^2 / D from the camera.
  const double rim_mm = kRadiusMm * std::sqrt(1.0 - std::pow(kRadiusMm / 300.0, 2));
  const double rim_z_mm = 300.0 - kRadiusMm * kRadiusMm / 300.0;
  const Eigen::Vector3d lo(10 - rim_mm - 30, 20 - rim_mm - 30, 30 + 250 - 30);
  const Eigen::Vector3d hi(10 + rim_mm + 30, 20 + rim_mm + 30, 30 + rim_z_mm + 30);
  EXPECT_LE((roi->min() - lo).cwiseAbs().maxCoeff(), kPixelFootprintMm) << roi->min().transpose();
  EXPECT_LE((roi->max() - hi).cwiseAbs().maxCoeff(), kPixelFootprintMm) << roi->max().transpose();
  // Nothing valid anywhere: no ROI.
  const Image<float> empty(128, 128, 0.0f);
  const RoiView nothing{&empty, tool_from_ahat};
  EXPECT_FALSE(AutomaticRoi({&nothing, 1}, camera, options));
}

TEST(AutomaticRoi, OneFrameLookingElsewhereDoesNotMoveIt) {
  // Five frames see the 50 mm sphere 300 mm ahead; the first sees only a second sphere 250 mm to
  // the side (a hand, the drape). The ROI is that of the five, not one around the stray view.
  const AhatCamera camera(SmallFisheyeCalibration(128));
  const Rigid3d tool_from_ahat(Eigen::Quaterniond::Identity(), Eigen::Vector3d(10, 20, 30));
  const Image<float> head = RenderSphere(camera, tool_from_ahat, {10, 20, 330}, 50.0);
  const Rigid3d turned(Eigen::Quaterniond::Identity(), Eigen::Vector3d(260, 20, 30));
  const Image<float> stray = RenderSphere(camera, turned, {260, 20, 330}, 50.0);
  AutoRoiOptions options;
  options.centre_window_px = 8;
  std::vector<RoiView> views = {{&stray, turned}};
  for (int k = 0; k < 5; ++k) views.push_back({&head, tool_from_ahat});
  const std::optional<Eigen::AlignedBox3d> roi = AutomaticRoi(views, camera, options);
  const RoiView alone{&head, tool_from_ahat};
  const std::optional<Eigen::AlignedBox3d> head_only = AutomaticRoi({&alone, 1}, camera, options);
  ASSERT_TRUE(roi && head_only);
  // The stray sphere is 250 mm off: none of it lies within the 150 mm radius of the centre.
  EXPECT_LE((roi->min() - head_only->min()).cwiseAbs().maxCoeff(), kExactTolMm);
  EXPECT_LE((roi->max() - head_only->max()).cwiseAbs().maxCoeff(), kExactTolMm);
  // Alone, the stray view would have placed the ROI around itself.
  const RoiView first{&stray, turned};
  EXPECT_GT(AutomaticRoi({&first, 1}, camera, options)->center().x(), 150.0);
}

TEST(ReconstructOptions, CheckNamesTheBadField) {
  ReconstructOptions options;
  EXPECT_NO_THROW(options.Check());
  options.frame_step = 0;
  EXPECT_THROW(options.Check(), PreconditionError);
  options = {};
  options.marker_mask_dilation_px = -1;
  EXPECT_THROW(options.Check(), PreconditionError);
  options = {};
  options.tsdf.voxel_size_mm = 0.0;
  EXPECT_THROW(options.Check(), PreconditionError);
  options = {};
  options.model_check.pixel_stride = 0;
  EXPECT_THROW(options.Check(), PreconditionError);
  options = {};
  options.pose_consistency.max_translation_mm = 0.0;
  EXPECT_THROW(options.Check(), PreconditionError);
}

TEST(SeldomObservedMinWeight, FramesOrFractionOfFramesCappedBelowTheWeightCap) {
  ReconstructOptions options;  // 5 frames and 5 % of the frames fused; weight cap 128
  EXPECT_DOUBLE_EQ(SeldomObservedMinWeight(options, 10), 5.0);
  EXPECT_DOUBLE_EQ(SeldomObservedMinWeight(options, 3), 1.5);  // half the frames fused
  EXPECT_DOUBLE_EQ(SeldomObservedMinWeight(options, 400), 20.0);
  EXPECT_DOUBLE_EQ(SeldomObservedMinWeight(options, 100000), 64.0);  // half the cap
  options.mesh.min_weight = 80.0;  // a user's larger threshold wins, cap or not
  EXPECT_DOUBLE_EQ(SeldomObservedMinWeight(options, 10), 80.0);
  options = {};
  options.min_observed_frames = 0.0;
  options.min_observed_fraction = 0.0;
  EXPECT_DOUBLE_EQ(SeldomObservedMinWeight(options, 400), 0.0);
  options.min_observed_fraction = 1.5;
  EXPECT_THROW(options.Check(), PreconditionError);
}

// A sphere in front of the head in 2 of 40 frames (a transient object the checks did not catch)
// is fused, but seen too seldom to be meshed with the default threshold; the head stays whole.
TEST(SeldomObservedMinWeight, ATransientObjectSeenInTwoFramesIsNotMeshed) {
  const AhatCamera camera(SmallFisheyeCalibration(128));
  const EllipsoidHead head;
  const Eigen::Vector3d forward(0.0, -1.0, 0.3);
  const std::vector<Rigid3d> poses = FrontPoses(head.centre_in_tool, forward, 0.5, 40, 7);
  const Eigen::Vector3d ghost = head.centre_in_tool + 140.0 * forward.normalized();
  constexpr double kGhostRadiusMm = 15.0;
  TsdfOptions tsdf;
  tsdf.roi_in_tool = Eigen::AlignedBox3d(head.centre_in_tool - Eigen::Vector3d::Constant(180.0),
                                         head.centre_in_tool + Eigen::Vector3d::Constant(180.0));
  TsdfVolume volume(tsdf, camera);
  std::mt19937_64 rng(3);
  for (std::size_t i = 0; i < poses.size(); ++i) {
    Image<float> range = head.Render(camera, poses[i], 0.5, rng);
    if (i == 5 || i == 6) {
      const Image<float> sphere = RenderSphere(camera, poses[i], ghost, kGhostRadiusMm);
      for (std::size_t p = 0; p < range.size(); ++p) {
        const float s = sphere.data()[p];
        if (s > 0.0f && (range.data()[p] == 0.0f || s < range.data()[p])) range.data()[p] = s;
      }
    }
    volume.Integrate(range, poses[i]);
  }
  const auto near_ghost = [&](const TriangleMesh& mesh) {
    return std::count_if(mesh.vertices.begin(), mesh.vertices.end(),
                         [&](const auto& v) { return (v - ghost).norm() < kGhostRadiusMm + 3.0; });
  };
  // Frames in which a head point faces the camera at under 60 deg incidence (grazing views
  // update the voxels only within the truncation of their coarse pixels) inside its field of
  // view (the ellipsoid is convex: nothing else hides it).
  const auto views = [&](const Eigen::Vector3d& v) {
    const Eigen::Vector3d q = head.rotation.transpose() * (v - head.centre_in_tool);
    const Eigen::Vector3d normal =
        head.rotation * q.cwiseQuotient(head.semi_axes_mm.cwiseAbs2()).normalized();
    return std::count_if(poses.begin(), poses.end(), [&](const Rigid3d& pose) {
      return normal.dot((pose.translation - v).normalized()) > 0.5 &&
             camera.Project(pose.Inverse() * v).has_value();
    });
  };
  const TriangleMesh all = ExtractIsoSurface(volume, {});
  TsdfMeshOptions seldom;
  seldom.min_weight = SeldomObservedMinWeight(ReconstructOptions{}, poses.size());
  const TriangleMesh kept = ExtractIsoSurface(volume, seldom);
  ASSERT_GT(near_ghost(all), 100);  // the ghost was fused and would be meshed
  EXPECT_EQ(near_ghost(kept), 0);
  // The head: kept where seen in well over the threshold's 5 frames (10: a cell's 8 corners
  // and the truncation band straddle a few views' rims), left out where seen in fewer than 3.
  std::size_t well_seen = 0, well_seen_kept = 0, seldom_kept = 0;
  const SurfaceDistance to_kept(kept);
  for (const Eigen::Vector3d& v : all.vertices) {
    if (std::abs(head.DistanceMm(v)) > 2.0) continue;
    const auto n = views(v);
    const bool is_kept = to_kept.Closest(v, 0.5).has_value();
    if (n >= 10) {
      ++well_seen;
      well_seen_kept += is_kept ? 1 : 0;
    } else if (n < 3 && is_kept) {
      ++seldom_kept;
    }
  }
  RecordProperty("well_seen_head_vertices", std::to_string(well_seen));
  EXPECT_GE(static_cast<double>(well_seen_kept), 0.99 * static_cast<double>(well_seen));
  EXPECT_EQ(seldom_kept, 0u);
}

TEST(ComputeSurfaceErrorStats, MedianIqrRmsOfAbsoluteValues) {
  const SurfaceErrorStats s = ComputeSurfaceErrorStats({-1.0, 2.0, 3.0, -4.0, 5.0});
  EXPECT_EQ(s.abs_mm.count, 5u);
  EXPECT_NEAR(s.abs_mm.median, 3.0, kExactTolMm);
  EXPECT_NEAR(s.abs_mm.iqr(), 2.0, kExactTolMm);  // quartiles 2 and 4 (linear interpolation)
  EXPECT_NEAR(s.mean_signed_mm, 1.0, kExactTolMm);
  EXPECT_NEAR(s.abs_mm.rms, std::sqrt(11.0), kExactTolMm);
  EXPECT_EQ(ComputeSurfaceErrorStats({}).abs_mm.count, 0u);
}

TriangleMesh Square(double z_mm) {  // 100 mm square in the plane z, normal +z
  TriangleMesh m;
  m.vertices = {{-50, -50, z_mm}, {50, -50, z_mm}, {50, 50, z_mm}, {-50, 50, z_mm}};
  m.triangles = {{0, 1, 2}, {0, 2, 3}};
  return m;
}

TEST(EvaluateReconstruction, AssignsVerticesToTheNearestObjectWithTableRows) {
  const std::vector<TruthSurface> truth = {{"hemisphere_size2", "nylon", false, Square(0.0)},
                                           {"head", "nylon", true, Square(100.0)}};
  TriangleMesh surface;
  surface.vertices = {{0, 0, 0.5},   {10, 0, 0.5},  {0, 10, 0.5},   // 0.5 mm in front of the shape
                      {0, 0, 99.75}, {5, 0, 99.75}, {0, 5, 99.75},  // 0.25 mm behind the head
                      {0, 0, 50.0}};                                // outlier
  surface.triangles = {{0, 1, 2}, {3, 4, 5}};
  const ReconstructionEvaluation e = EvaluateReconstruction(surface, truth);
  EXPECT_EQ(e.vertices, 7u);
  EXPECT_EQ(e.outliers, 1u);
  ASSERT_EQ(e.objects.size(), 2u);
  EXPECT_EQ(e.objects[0].row, "HS");
  EXPECT_EQ(e.objects[0].size, 2);
  EXPECT_NEAR(e.objects[0].stats.abs_mm.median, 0.5, kExactTolMm);
  EXPECT_NEAR(e.objects[0].stats.mean_signed_mm, 0.5, kExactTolMm);
  EXPECT_EQ(e.objects[1].row, "H");
  EXPECT_NEAR(e.objects[1].stats.mean_signed_mm, -0.25, kExactTolMm);
  EXPECT_EQ(e.all.abs_mm.count, 6u);
  ASSERT_EQ(e.colored.vertex_colors.size(), 7u);
  EXPECT_NEAR(e.colored.vertex_scalars[0], 0.5f, 1e-6f);
  EXPECT_TRUE(std::isnan(e.colored.vertex_scalars[6]));  // the outlier has no error
}

}  // namespace
}  // namespace tofnav
