// SPDX-License-Identifier: BSD-3-Clause
// Steps a scenario frame by frame: timing, mount and camera poses, rendering, per-frame truth.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <optional>
#include <random>
#include <vector>

#include "tofnav/core/rigid3d.hpp"
#include "tofnav/sensor/ahat_calibration.hpp"
#include "tofnav/sensor/ahat_camera.hpp"
#include "tofnav/sim/render.hpp"
#include "tofnav/sim/scenario.hpp"

namespace tofnav::sim {

/// What hides a marker's centre from the camera: a scene object or another tool's marker.
struct MarkerOccluder {
  int object = -1;  // index into Scene::objects
  int tool = -1;    // index into Scene::tools (a marker of it)
  bool hidden() const { return object >= 0 || tool >= 0; }
};

/// One simulated frame and its ground truth.
struct SimulatedFrame {
  std::int64_t index = 0;  // frame number in the output
  std::int64_t slot = 0;   // nominal frame slot (index + dropped slots before it)
  /// render.frame carries host_ticks, sensor_ticks_ns and the reported (jittered) world_from_rig.
  RenderResult render;
  Rigid3d world_from_rig_true;             // the pose the frame was rendered from
  std::vector<Rigid3d> ahat_from_tools;    // per scene tool
  std::vector<Rigid3d> ahat_from_objects;  // per scene object
  /// Per render.markers entry: where its centre projects (our pixel coordinates), if it does.
  std::vector<std::optional<Eigen::Vector2d>> marker_pixels;
  /// Per render.markers entry: what hides its centre (the first hit of the pixel it projects into
  /// lies more than a marker radius + 1 mm in front of it), if anything.
  std::vector<MarkerOccluder> marker_occluders;
};

/// What hides each marker of `frame` (SimulatedFrame::marker_occluders).
std::vector<MarkerOccluder> MarkerOccluders(const Scene& scene, const SimulatedFrame& frame);

/// World poses at frame slot `slot` of every mount of `scenario` (index order), with the seeds
/// the Simulator uses.
std::vector<Rigid3d> ScenarioMountPoses(const Scenario& scenario, std::int64_t slot);
/// world_from_ahat of the scenario's camera at frame slot `slot`.
Rigid3d ScenarioCameraPose(const Scenario& scenario, std::int64_t slot);

/// The headset's AHAT calibration and camera model, built from the calibration options (about
/// 0.1 s in Release, far more unoptimised): share one between simulators whose scenarios have
/// the same camera.calibration.
struct SimulatorCamera {
  explicit SimulatorCamera(const SyntheticAhatOptions& calibration_options);
  /// A real device's calibration (CameraSetup::device) instead of the synthetic model.
  explicit SimulatorCamera(std::shared_ptr<const AhatCalibration> device_calibration);
  SyntheticAhatOptions options;
  std::shared_ptr<const AhatCalibration> device;  // null for the synthetic model
  AhatCalibration calibration;
  AhatCamera camera;
};

/// Renders the frames of a scenario in order. Everything random derives from scenario.seed, so
/// the same scenario gives the same frames. Keeps a reference to `scenario`.
class Simulator {
 public:
  /// `camera` (optional) must have been built from scenario.camera.calibration.
  explicit Simulator(const Scenario& scenario,
                     std::shared_ptr<const SimulatorCamera> camera = nullptr);
  ~Simulator();
  Simulator(const Simulator&) = delete;
  Simulator& operator=(const Simulator&) = delete;

  /// The AHAT calibration the frames are rendered with (write it next to the recording).
  const AhatCalibration& calibration() const { return camera_->calibration; }
  const AhatCamera& camera() const { return camera_->camera; }
  bool done() const { return next_index_ >= scenario_.frames; }
  std::int64_t dropped_slots() const { return clock_.dropped_slots(); }
  /// Slots skipped because no hand was in view (FrameTimingOptions::no_hand_rate_hz).
  std::int64_t throttled_slots() const { return clock_.throttled_slots(); }

  /// Renders the next frame; PreconditionError when done().
  SimulatedFrame Next();

 private:
  bool HandInView(std::int64_t slot) const;

  const Scenario& scenario_;
  std::shared_ptr<const SimulatorCamera> camera_;
  Scene scene_;  // the scenario's scene with world poses of the current frame
  std::unique_ptr<AhatRenderer> renderer_;
  FrameClock clock_;
  std::mt19937_64 render_rng_;
  std::mt19937_64 slam_rng_;
  std::int64_t next_index_ = 0;
};

}  // namespace tofnav::sim
