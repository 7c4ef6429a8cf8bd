// SPDX-License-Identifier: BSD-3-Clause
// Acceptance of f_rf (Eq. 1-2, with the entrance-angle term of docs/tracking.md 4) fitted from a
// rendered linear-stage recording at four tilts (Sec. III-A.1).
#include <gtest/gtest.h>

#include <numbers>
#include <random>

#include "e2e_common.hpp"
#include "tofnav/markers/marker_centre.hpp"
#include "tofnav/tracking/linear_stage.hpp"
#include "tofnav/tracking/tool_pose.hpp"
#include "tracking_test_tools.hpp"

namespace tofnav {
namespace {

// The tape's entrance-angle term as the paper's linear stage measured it (1.08 mm between its
// 0 and 30 deg runs: docs/simulator.md 10), rendered in every scene of this test.
constexpr double kTapeEntranceGainMmPerRad = 2.1;

// 4 x 4 sub-rays: see tracking_e2e_test.cpp (2 x 2 jittered rays add rim coverage noise).
sim::RenderResult RenderStructure(sim::RetroCurve curve, const Rigid3d& pose, std::uint64_t seed);

sim::Scene StructureScene(sim::RetroCurve curve, const Rigid3d& ahat_from_structure) {
  int retro = 0;
  sim::Scene scene = testing::WallScene(1500.0, retro, curve, kTapeEntranceGainMmPerRad);
  const int board = scene.AddMaterial(sim::DiffuseMaterial(0.3));
  scene.AddObject("board", sim::PlaneMesh(170.0, 130.0), board, ahat_from_structure);
  sim::Tool tool{"stage", {}, ahat_from_structure};
  for (const Eigen::Vector3d& p : testing::StageStructure(0.1).markers_in_tool) {
    tool.markers.push_back(sim::DiscMarkerOnSurface(p - Eigen::Vector3d(0, 0, 0.1),
                                                    Eigen::Vector3d::UnitZ(), 10.0, retro, 0.1));
  }
  scene.AddTool(tool);
  return scene;
}

sim::RenderResult RenderStructure(sim::RetroCurve curve, const Rigid3d& pose, std::uint64_t seed) {
  sim::RenderOptions options;
  options.supersampling = 4;
  return testing::RenderMarkers(StructureScene(curve, pose), seed, options);
}

// Bias of corrected disc-centre ranges [mm] per 100 mm bin over 300-700 mm: Eq. (2) with each
// disc's entrance angle from the structure's true pose (as tracking has it from its pose).
std::vector<double> CentreRangeBias(sim::RetroCurve curve, const MarkerRangeModel& model,
                                    std::mt19937_64& rng, std::vector<double>& uncorrected) {
  std::vector<std::vector<double>> bins(4), raw_bins(4);
  std::uniform_real_distribution<double> z(300.0, 700.0);
  for (int f = 0; f < 80; ++f) {
    const Rigid3d pose = testing::RandomFacingPose(rng, z(rng), 0.3);
    const sim::RenderResult r = RenderStructure(curve, pose, rng());
    const std::vector<DetectedMarker> raw = LocateMarkers(r.frame, testing::TestCamera()).markers;
    std::vector<DetectedMarker> corrected = CorrectMarkerRanges(raw, model);
    const Eigen::Vector3d normal = pose.rotation * Eigen::Vector3d::UnitZ();
    for (DetectedMarker& m : corrected) {
      ShiftMarkerRange(m, -model.entrance_gain_mm_per_rad *
                              std::acos(std::min(1.0, std::abs(normal.dot(m.ray_in_ahat)))));
    }
    for (std::size_t i = 0; i < raw.size(); ++i) {
      // The true marker nearest to the detection's ray.
      const sim::MarkerTruth* best = nullptr;
      double best_angle = 1.0;
      for (const sim::MarkerTruth& m : r.markers) {
        const double angle =
            std::acos(std::min(1.0, m.centre_in_ahat.normalized().dot(raw[i].ray_in_ahat)));
        if (angle < best_angle) best_angle = angle, best = &m;
      }
      if (best == nullptr || best_angle > 0.01) continue;
      const double truth_mm = best->centre_in_ahat.norm();
      const auto bin = static_cast<std::size_t>(std::clamp((truth_mm - 300.0) / 100.0, 0.0, 3.0));
      bins[bin].push_back(CentreRangeMm(corrected[i], 0.0, corrected[i].surface_range_mm) -
                          truth_mm);
      raw_bins[bin].push_back(CentreRangeMm(raw[i], 0.0, raw[i].surface_range_mm) - truth_mm);
    }
  }
  std::vector<double> bias;
  uncorrected.clear();
  for (std::size_t b = 0; b < 4; ++b) {
    bias.push_back(testing::Mean(bins[b]));
    uncorrected.push_back(testing::Mean(raw_bins[b]));
  }
  return bias;
}

// Position RMS [mm] of the 4-sphere reference tool over 300-700 mm with `model` applied: f_rf
// measured on tape discs, used on spheres.
double SphereToolPositionRms(sim::RetroCurve curve, const MarkerRangeModel& model,
                             std::mt19937_64& rng) {
  const ToolGeometry tools[] = {testing::ReferenceTool()};
  std::uniform_real_distribution<double> z(300.0, 700.0);
  std::vector<double> errors;
  for (int f = 0; f < 60; ++f) {
    const Rigid3d truth = testing::RandomFacingPose(rng, z(rng), 0.5);
    int retro = 0;
    sim::Scene scene = testing::WallScene(1000.0, retro, curve, kTapeEntranceGainMmPerRad);
    scene.AddTool(testing::SphereTool("reference", tools[0].markers_in_tool, 11.5, retro, truth));
    sim::RenderOptions options;
    options.supersampling = 4;
    const sim::RenderResult r = testing::RenderMarkers(scene, rng(), options);
    const std::vector<DetectedMarker> detections =
        CorrectMarkerRanges(LocateMarkers(r.frame, testing::TestCamera()).markers, model);
    ToolPoseOptions pose_options;  // each sphere pixel's entrance angle from the pose
    pose_options.marker_entrance_gain_mm_per_rad = model.entrance_gain_mm_per_rad;
    const ToolPoseResult pose = EstimateToolPoses(detections, tools, {}, pose_options)[0];
    if (pose.ahat_from_tool) errors.push_back(TranslationDistanceMm(*pose.ahat_from_tool, truth));
  }
  return testing::Rms(errors);
}

TEST(MarkerRangeAcceptance, FrfFittedFromAStageRecordingRemovesTheRangeBias) {
  // Single frames over 300-700 mm: the calibrated simulator's range noise (range^1.5 per pixel,
  // docs/simulator.md 10.1) gives the tool 0.21 mm RMS with the true f_rf (TrackingAcceptance);
  // 60 frames with the fitted one: 0.22-0.25 mm (0.25 was the line on the flat-floor simulator).
  constexpr double kMaxSpherePositionRmsMm = 0.30;
  constexpr double kMaxBiasMm = 0.2;  // the target, with a 4 mm f_rf span
  // The stage reference's own depth bias: +0.02 mm with the reference centroid's rays on a
  // face-on structure, +0.09 mm with the AB-weighted centroid's (pulled towards the image
  // centre by the illumination); +0.04 / +0.08 mm over runs tilted up to 30 deg (one rotation
  // and line fitted to each run's rays).
  constexpr double kMaxReferenceBiasMm = 0.1;
  const double gain = kTapeEntranceGainMmPerRad;
  for (const sim::RetroCurve curve : {sim::RetroCurve::kLinear, sim::RetroCurve::kSigmoid}) {
    std::mt19937_64 rng(static_cast<std::uint64_t>(curve));
    // The paper's stage: four runs tilted 0, 10, 20 and 30 deg, each 280 -> 720 mm at a
    // constant 27.5 mm/s, 10 Hz, 40 frames.
    std::vector<MarkerRangeSample> samples;
    std::vector<double> reference_error;  // PnP + line position along z against the truth
    int frames_used = 0;
    double line_rms_mm = 0.0;
    for (int run = 0; run < 4; ++run) {
      const double tilt_rad = (0.05 + 10.0 * run) * std::numbers::pi / 180.0;
      std::vector<StageFrame> frames;
      for (int f = 0; f < 40; ++f) {
        const double t = 0.4 * f;
        const Rigid3d pose = testing::FacingToolPose({12.0, -8.0, 280.0 + 27.5 * t}, tilt_rad, 0.1);
        const sim::RenderResult r = RenderStructure(curve, pose, rng());
        frames.push_back({t, LocateMarkers(r.frame, testing::TestCamera()).markers});
      }
      const StageRangeErrorResult stage =
          MeasureMarkerRangeErrors(frames, testing::StageStructure(0.1));
      for (int f = 0; f < 40; ++f) {
        const double t = 0.4 * f;
        const Eigen::Vector3d on_line = stage.line_origin_mm + stage.line_velocity_mm_per_s * t;
        reference_error.push_back(on_line.z() - (280.0 + 27.5 * t));
      }
      samples.insert(samples.end(), stage.samples.begin(), stage.samples.end());
      frames_used += stage.frames_used;
      line_rms_mm = std::max(line_rms_mm, stage.line_rms_mm);
    }
    std::printf("PnP + line reference depth error: mean %+.3f mm, RMS %.3f mm\n",
                testing::Mean(reference_error), testing::Rms(reference_error));
    EXPECT_LE(std::abs(testing::Mean(reference_error)), kMaxReferenceBiasMm);
    const MarkerRangeFitResult fit = FitMarkerRangeModel(samples);
    std::printf(
        "curve %d: %d frames, %zu samples, worst line RMS %.3f mm, p %.3g, dof %.1f, residual "
        "RMS %.3f mm, entrance gain %.3f mm/rad (simulated %.2f)\n",
        static_cast<int>(curve), frames_used, samples.size(), line_rms_mm, fit.fit.smoothing_p,
        fit.fit.effective_dof, fit.rms_residual_mm, fit.model.entrance_gain_mm_per_rad, gain);
    // The four tilts measure the gain: 1.77-1.88 mm/rad of the 2.1 rendered (1.68-1.73 while
    // each frame was posed alone, whose frontal runs lay too near: docs/tracking.md 4; 40 frames
    // a run still leave each run's reference ~0.05 mm off); within 0.5 mm/rad, 0.26 mm at 30
    // deg. What matters is below: the corrected bias and the sphere tool.
    EXPECT_NEAR(fit.model.entrance_gain_mm_per_rad, gain, 0.5);
    std::vector<double> uncorrected;
    const std::vector<double> bias = CentreRangeBias(curve, fit.model, rng, uncorrected);
    for (std::size_t b = 0; b < bias.size(); ++b) {
      std::printf("  %3zu-%3zu mm: centre range bias %+.3f mm corrected, %+.3f mm raw\n",
                  300 + 100 * b, 400 + 100 * b, bias[b], uncorrected[b]);
      EXPECT_LE(std::abs(bias[b]), kMaxBiasMm) << b;
    }
    const double sphere_rms = SphereToolPositionRms(curve, fit.model, rng);
    std::printf("  sphere reference tool with this f_rf: position RMS %.3f mm\n", sphere_rms);
    EXPECT_LE(sphere_rms, kMaxSpherePositionRmsMm);
  }
}

}  // namespace
}  // namespace tofnav
