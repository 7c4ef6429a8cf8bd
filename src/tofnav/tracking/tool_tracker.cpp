// SPDX-License-Identifier: BSD-3-Clause
// ToolTracker: EstimateToolPoses with a temporal prior, then one PoseFilter per tool.
#include "tofnav/tracking/tool_tracker.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include "tofnav/core/require.hpp"

namespace tofnav {
namespace {

// A pose's noise variance relative to one at `from_mm`: (range / from_mm)^(2 exponent), never
// below 1 (ToolTrackerOptions::noise_growth_exponent).
double RangeVarianceScale(double range_mm, double from_mm, double exponent) {
  return std::max(1.0, std::pow(range_mm / from_mm, 2.0 * exponent));
}

// The markers' centroid in `tool`: the filters run on the pose of a frame there
// (ToolTracker::centroid_in_tool_).
Eigen::Vector3d MarkerCentroid(const ToolGeometry& tool) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& m : tool.markers_in_tool) sum += m;
  return sum / static_cast<double>(std::max<std::size_t>(1, tool.markers_in_tool.size()));
}

// ahat_from_tool shifted to (+) or back from (-) the frame at `centroid_in_tool` (same axes).
Rigid3d Shifted(const Rigid3d& ahat_from_frame, const Eigen::Vector3d& offset) {
  return Rigid3d(ahat_from_frame.rotation, ahat_from_frame * offset);
}

// The frame's world-fixed tools' positions fused again, the rig pose's error shared
// (ToolTrackerOptions::share_rig_error): only tools the world filter fused this frame take part.
void FuseSharedRigError(std::vector<std::optional<Rigid3d>>& filtered_of,
                        const std::vector<std::optional<WorldPointTerms>>& terms_of,
                        double rig_variance_mm2, double gate_chi2) {
  std::vector<WorldPointTerms> points;
  std::vector<std::size_t> tool_of;
  for (std::size_t t = 0; t < filtered_of.size(); ++t) {
    if (filtered_of[t] && terms_of[t]) {
      points.push_back(*terms_of[t]);
      tool_of.push_back(t);
    }
  }
  if (points.size() < 2) return;  // alone, each tool is fused already
  const std::vector<Eigen::Vector3d> fused =
      FuseWithSharedRigError(points, rig_variance_mm2, gate_chi2);
  for (std::size_t i = 0; i < points.size(); ++i) filtered_of[tool_of[i]]->translation = fused[i];
}

}  // namespace

void ToolTrackerOptions::Check() const {
  pose.Check();
  filter.Check();
  world_position.Check();
  Require(max_missed_frames >= 1, "ToolTrackerOptions::max_missed_frames must be >= 1");
  Require(std::isfinite(world_max_gap_s) && world_max_gap_s > 0.0,
          "ToolTrackerOptions::world_max_gap_s must be > 0");
  Require(std::isfinite(world_rate_sigma_rad_per_s) && world_rate_sigma_rad_per_s > 0.0,
          "ToolTrackerOptions::world_rate_sigma_rad_per_s must be > 0");
  Require(std::isfinite(world_accel_sigma_rad_per_s2) && world_accel_sigma_rad_per_s2 > 0.0,
          "ToolTrackerOptions::world_accel_sigma_rad_per_s2 must be > 0");
  Require(std::isfinite(world_still_sigma_rad_per_s) && world_still_sigma_rad_per_s >= 0.0,
          "ToolTrackerOptions::world_still_sigma_rad_per_s must be >= 0");
  Require(std::isfinite(world_still_dwell_s) && world_still_dwell_s > 0.0 &&
              std::isfinite(world_turning_dwell_s) && world_turning_dwell_s > 0.0,
          "ToolTrackerOptions: world_still_dwell_s and world_turning_dwell_s must be > 0");
  Require(std::isfinite(noise_growth_range_mm) && noise_growth_range_mm > 0.0 &&
              std::isfinite(rotation_noise_growth_range_mm) &&
              rotation_noise_growth_range_mm > 0.0 && std::isfinite(noise_growth_exponent) &&
              noise_growth_exponent >= 0.0,
          "ToolTrackerOptions: the noise growth ranges must be > 0 and noise_growth_exponent >= 0");
  Require(std::isfinite(partial_variance_scale) && partial_variance_scale >= 1.0,
          "ToolTrackerOptions::partial_variance_scale must be >= 1");
  Require(camera_motion_bandwidth_per_s >= 0.0 && camera_motion_baseline_s > 0.0,
          "ToolTrackerOptions: camera_motion_bandwidth_per_s must be >= 0 and "
          "camera_motion_baseline_s > 0");
}

ToolTracker::ToolTracker(std::vector<ToolGeometry> tools, const ToolTrackerOptions& options)
    : tools_(std::move(tools)), options_(options), rig_jitter_(options.world_position) {
  options.Check();
  for (const ToolGeometry& tool : tools_) {
    tool.Check();
    centroid_in_tool_.push_back(MarkerCentroid(tool));
  }
  filters_.assign(tools_.size(), PoseFilter(options.filter));
  WorldOrientationOptions world;
  world.rotation_sigma_rad = options.filter.rotation_sigma_rad;
  world.turning_rate_sigma_rad_per_s =
      std::min(options.filter.boost_rate_sigma_rad_per_s, options.world_rate_sigma_rad_per_s);
  world.turning_accel_sigma_rad_per_s2 = std::min(options.filter.rotation_accel_sigma_rad_per_s2,
                                                  options.world_accel_sigma_rad_per_s2);
  world.still_sigma_rad_per_s = options.world_still_sigma_rad_per_s;
  world.still_dwell_s = options.world_still_dwell_s;
  world.turning_dwell_s = options.world_turning_dwell_s;
  world.gate_chi2 = options.filter.gate_chi2;
  world.gate_floor_rad = options.filter.gate_floor_rad;
  world.boost_chi2 = options.filter.boost_chi2;
  world.max_gated = options.filter.max_gated;
  world.max_gap_s = std::max(options.filter.max_gap_s, options.world_max_gap_s);
  world_filters_.assign(tools_.size(), WorldOrientationFilter(world));
  world_positions_.assign(tools_.size(), WorldPositionFilter(options.world_position));
  Reset();
}

void ToolTracker::Reset() {
  for (PoseFilter& f : filters_) f.Reset();
  for (WorldOrientationFilter& f : world_filters_) f.Reset();
  for (WorldPositionFilter& f : world_positions_) f.Reset();
  rig_jitter_.Reset();
  last_pose_.assign(tools_.size(), std::nullopt);
  last_seen_s_.assign(tools_.size(), 0.0);
  missed_.assign(tools_.size(), 0);
  camera_poses_.clear();
}

TrackingFrame ToolTracker::Track(std::span<const DetectedMarker> detections, double timestamp_s,
                                 const std::optional<Rigid3d>& world_from_ahat,
                                 std::span<const DroppedBlob> dropped,
                                 const MarkerVoidTest* void_test) {
  const bool in_world = options_.filter_enabled && options_.rotation_in_world && world_from_ahat;
  // ahat(now)_from_ahat(then), `then` about camera_motion_baseline_s ago, from the camera poses.
  std::optional<Rigid3d> camera_step;
  double step_s = 0.0;
  if (!world_from_ahat || (!camera_poses_.empty() && timestamp_s <= camera_poses_.back().first)) {
    camera_poses_.clear();
  }
  if (world_from_ahat) {
    const double baseline_s = options_.camera_motion_baseline_s;
    while (camera_poses_.size() >= 2 && timestamp_s - camera_poses_[1].first >= baseline_s) {
      camera_poses_.pop_front();  // keep the newest pose at least baseline_s old at the front
    }
    if (!camera_poses_.empty()) {
      step_s = timestamp_s - camera_poses_.front().first;
      if (step_s >= 0.5 * baseline_s && step_s <= 2.0 * baseline_s) {
        camera_step = world_from_ahat->Inverse() * camera_poses_.front().second;
      }
    }
    camera_poses_.emplace_back(timestamp_s, *world_from_ahat);
  }
  std::vector<std::optional<Rigid3d>> prior(tools_.size());
  for (std::size_t t = 0; t < tools_.size(); ++t) {
    if (options_.filter_enabled) {
      if (const auto predicted = filters_[t].Predict(timestamp_s)) {
        prior[t] = Shifted(*predicted, -centroid_in_tool_[t]);
      }
    } else if (last_pose_[t] && timestamp_s - last_seen_s_[t] <= options_.filter.max_gap_s) {
      prior[t] = last_pose_[t];
    }
  }
  TrackingFrame frame;
  frame.timestamp_s = timestamp_s;
  // Per tool: its filtered pose of the centroid frame, and the world position's fusion terms.
  std::vector<std::optional<Rigid3d>> filtered_of(tools_.size());
  std::vector<std::optional<WorldPointTerms>> terms_of(tools_.size());
  std::vector<ToolPoseResult> poses =
      EstimateToolPoses(detections, tools_, prior, options_.pose, dropped, void_test);
  for (std::size_t t = 0; t < tools_.size(); ++t) {
    TrackedTool tracked;
    tracked.measurement = std::move(poses[t]);
    const std::optional<Rigid3d>& raw = tracked.measurement.ahat_from_tool;
    if (!raw) {
      if (++missed_[t] >= options_.max_missed_frames) {  // a loss: drop the prior and the state
        // ... in `ahat`; the world filter keeps its orientation over a look-away up to
        // world_max_gap_s: there the tool stands still, and its gate restarts it if it did not.
        filters_[t].Reset();
        last_pose_[t].reset();
      }
      frame.tools.push_back(std::move(tracked));
      continue;
    }
    missed_[t] = 0;
    last_pose_[t] = raw;
    last_seen_s_[t] = timestamp_s;
    if (options_.filter_enabled) {
      // The filters hold the pose of the markers' centroid frame: its position is what the
      // markers fix best, so a tool whose origin lies far from its markers (a headframe's first
      // plate, a pointer's tip) does not get the orientation's noise times that lever in its
      // filtered position, and the world filter's orientation turns the pose about the markers.
      const Rigid3d measured = Shifted(*raw, centroid_in_tool_[t]);
      double accel_sigma = 0.0;  // the option's
      if (camera_step) {         // a world-fixed point at the markers was at step^-1 * p then
        const Eigen::Vector3d& p = measured.translation;
        const double speed_mm_per_s = (p - camera_step->Inverse() * p).norm() / step_s;
        accel_sigma = std::max(options_.filter.position_accel_sigma_mm_per_s2,
                               options_.camera_motion_bandwidth_per_s * speed_mm_per_s);
      }
      const ToolPoseResult& m = tracked.measurement;
      const int dof = 3 * m.used_markers - 6;
      const double fit_scale = options_.inflate_noise_by_fit && dof > 0
                                   ? std::max(1.0, m.noise_chi2 / static_cast<double>(dof))
                                   : 1.0;
      // In the world filters, a pose matched on fewer than all of the tool's markers counts for
      // less (ToolTrackerOptions::partial_variance_scale).
      const double world_scale =
          fit_scale *
          (m.status == ToolStatus::kPartiallyOccluded ? options_.partial_variance_scale : 1.0);
      const double range_mm = measured.translation.norm();
      const double range_scale = RangeVarianceScale(range_mm, options_.noise_growth_range_mm,
                                                    options_.noise_growth_exponent);
      // In full while the camera stands still; fading as its motion raises the process noise:
      // then the filter must follow the camera, and a lower gain made it lag (demo: 0.27 -> 0.34).
      const double still =
          accel_sigma > 0.0 ? options_.filter.position_accel_sigma_mm_per_s2 / accel_sigma : 1.0;
      const double position_scale = 1.0 + (range_scale - 1.0) * still;
      const double rotation_scale = RangeVarianceScale(
          range_mm, options_.rotation_noise_growth_range_mm, options_.noise_growth_exponent);
      // With a world filter the orientation is judged there, where the tool stands still; in
      // `ahat` it turns with the head, faster than the filter's rotation noise follows at 6 Hz.
      const PoseFilterUpdate update =
          filters_[t].Update(measured, timestamp_s,
                             {.position_accel_sigma_mm_per_s2 = accel_sigma,
                              .measurement_variance_scale = fit_scale,
                              .position_variance_scale = position_scale,
                              .rotation_variance_scale = rotation_scale,
                              .gate_on_rotation = !in_world});
      tracked.gated = update.gated;
      tracked.filter_reset = update.reset;
      Rigid3d filtered = update.filtered;  // of the centroid frame
      if (!in_world) {
        world_filters_[t].Reset();
        world_positions_[t].Reset();
      } else {
        const WorldOrientationUpdate world = world_filters_[t].Update(
            (*world_from_ahat * measured).rotation, timestamp_s, world_scale * rotation_scale);
        // Gated there, the world filter's output is its prediction: the held orientation of a
        // tool that stands still, better than the raw one the `ahat` filter may restart from.
        filtered.rotation = world_from_ahat->rotation.inverse() * world.filtered;
        if (!update.gated && m.rotation_sd_rad > 0.0) {  // with a filtered pose only
          tracked.filtered_rotation_sd_rad =
              std::sqrt(3.0 * world.variance_ratio * world_scale) * m.rotation_sd_rad;
        }
        if (options_.position_in_world) {
          // Fused with the `ahat` filter's position: while the camera stands still it averages
          // many frames (its variance ratio small), while it moves it is the raw one's.
          const WorldPositionUpdate position = world_positions_[t].Update(
              {.measured_in_ahat = measured.translation,
               .variance_scale = world_scale,
               .estimate_in_ahat = filtered.translation,
               .estimate_variance_ratio = update.gated ? 1.0 : update.position_variance_ratio},
              *world_from_ahat, timestamp_s, rig_jitter_);
          if (position.fused_in_ahat) filtered.translation = *position.fused_in_ahat;
          terms_of[t] = position.terms;
        }
      }
      if (!update.gated) filtered_of[t] = filtered;
    }
    frame.tools.push_back(std::move(tracked));
  }
  if (options_.share_rig_error) {
    FuseSharedRigError(filtered_of, terms_of, rig_jitter_.variance_mm2(),
                       options_.world_position.gate_chi2);
  }
  for (std::size_t t = 0; t < tools_.size(); ++t) {
    if (filtered_of[t]) {
      frame.tools[t].filtered_ahat_from_tool = Shifted(*filtered_of[t], -centroid_in_tool_[t]);
    }
  }
  return frame;
}

}  // namespace tofnav
