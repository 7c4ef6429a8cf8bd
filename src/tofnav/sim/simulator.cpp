// SPDX-License-Identifier: BSD-3-Clause
// The frame loop of a scenario.
#include "tofnav/sim/simulator.hpp"

#include <cmath>
#include <utility>

#include "tofnav/core/require.hpp"
#include "tofnav/sim/random.hpp"

namespace tofnav::sim {
namespace {

bool SameOptions(const SyntheticAhatOptions& a, const SyntheticAhatOptions& b) {
  return a.focal_px == b.focal_px && a.principal_point_px == b.principal_point_px &&
         a.aspect_y == b.aspect_y && a.cubic_rad_per_px3 == b.cubic_rad_per_px3 &&
         a.fold_radius_px == b.fold_radius_px && a.sample_offset_px == b.sample_offset_px &&
         a.pinhole_focal_px == b.pinhole_focal_px &&
         a.rig_from_ahat.rotation.coeffs() == b.rig_from_ahat.rotation.coeffs() &&
         a.rig_from_ahat.translation == b.rig_from_ahat.translation;
}

std::shared_ptr<const SimulatorCamera> CheckedCamera(
    const Scenario& scenario, std::shared_ptr<const SimulatorCamera> camera) {
  scenario.Check();
  if (!camera && scenario.camera.device) {
    return std::make_shared<const SimulatorCamera>(scenario.camera.device);
  }
  if (!camera) return std::make_shared<const SimulatorCamera>(scenario.camera.calibration);
  Require(camera->device == scenario.camera.device &&
              (camera->device || SameOptions(camera->options, scenario.camera.calibration)),
          "Simulator: the shared camera was built for other calibration options");
  return camera;
}

// world_from_mount * mount_from_x, or world_from_x itself for mount -1.
Rigid3d InWorld(const std::vector<Rigid3d>& world_from_mounts, int mount,
                const Rigid3d& mount_from_x) {
  return mount < 0 ? mount_from_x
                   : world_from_mounts[static_cast<std::size_t>(mount)] * mount_from_x;
}

}  // namespace

SimulatorCamera::SimulatorCamera(const SyntheticAhatOptions& calibration_options)
    : options(calibration_options),
      calibration(MakeSyntheticAhatCalibration(calibration_options)),
      camera(calibration) {}

SimulatorCamera::SimulatorCamera(std::shared_ptr<const AhatCalibration> device_calibration)
    : device((Require(device_calibration != nullptr, "SimulatorCamera: no device calibration"),
              std::move(device_calibration))),
      calibration(*device),
      camera(calibration) {}

Simulator::Simulator(const Scenario& scenario, std::shared_ptr<const SimulatorCamera> camera)
    : scenario_(scenario),
      camera_(CheckedCamera(scenario, std::move(camera))),
      scene_(scenario.scene),
      renderer_(std::make_unique<AhatRenderer>(scenario.scene, camera_->camera)),
      clock_(scenario.timing, StreamSeed(scenario.seed, SeedStream::kFrameDrops)),
      render_rng_(StreamSeed(scenario.seed, SeedStream::kRender)),
      slam_rng_(StreamSeed(scenario.seed, SeedStream::kSlamJitter)) {}

Simulator::~Simulator() = default;

std::vector<Rigid3d> ScenarioMountPoses(const Scenario& scenario, std::int64_t slot) {
  std::vector<Rigid3d> poses;
  for (std::size_t m = 0; m < scenario.mounts.size(); ++m) {
    poses.push_back(MotionPose(scenario.mounts[m].motion, slot, scenario.timing.rate_hz,
                               StreamSeed(scenario.seed, SeedStream::kMounts, m)));
  }
  return poses;
}

Rigid3d ScenarioCameraPose(const Scenario& scenario, std::int64_t slot) {
  return MotionPose(scenario.camera.motion, slot, scenario.timing.rate_hz,
                    StreamSeed(scenario.seed, SeedStream::kCamera));
}

bool Simulator::HandInView(std::int64_t slot) const {
  // The headset's hand tracker sees a hand that is in the AHAT image within arm's reach; its
  // vertices stand in for the hand (docs/simulator.md 6.8).
  constexpr double kHandTrackingRangeMm = 1000.0;
  const std::vector<Rigid3d> world_from_mounts = ScenarioMountPoses(scenario_, slot);
  const Rigid3d ahat_from_world = ScenarioCameraPose(scenario_, slot).Inverse();
  for (std::size_t o = 0; o < scenario_.scene.objects.size(); ++o) {
    const SceneObject& object = scenario_.scene.objects[o];
    if (!object.name.starts_with("hand")) continue;
    const Rigid3d ahat_from_object =
        ahat_from_world *
        InWorld(world_from_mounts, scenario_.object_mounts[o], object.scene_from_object);
    const std::size_t step = std::max<std::size_t>(1, object.mesh.vertices.size() / 64);
    for (std::size_t v = 0; v < object.mesh.vertices.size(); v += step) {
      const Eigen::Vector3d p = ahat_from_object * object.mesh.vertices[v];
      if (p.z() <= 0.0 || p.norm() > kHandTrackingRangeMm) continue;
      if (camera().Project(p)) return true;
    }
  }
  return false;
}

SimulatedFrame Simulator::Next() {
  Require(!done(), "Simulator::Next: all frames have been rendered");
  SimulatedFrame out;
  out.index = next_index_++;
  out.slot = clock_.NextSlot([this](std::int64_t slot) { return HandInView(slot); });
  const std::vector<Rigid3d> world_from_mounts = ScenarioMountPoses(scenario_, out.slot);
  for (std::size_t o = 0; o < scene_.objects.size(); ++o) {
    scene_.objects[o].scene_from_object = InWorld(world_from_mounts, scenario_.object_mounts[o],
                                                  scenario_.scene.objects[o].scene_from_object);
  }
  for (std::size_t t = 0; t < scene_.tools.size(); ++t) {
    scene_.tools[t].scene_from_tool = InWorld(world_from_mounts, scenario_.tool_mounts[t],
                                              scenario_.scene.tools[t].scene_from_tool);
  }
  const Rigid3d world_from_ahat = ScenarioCameraPose(scenario_, out.slot);
  out.render = renderer_->Render(scene_, world_from_ahat, scenario_.render, render_rng_);
  out.world_from_rig_true = world_from_ahat * camera().rig_from_ahat().Inverse();
  AhatFrame& frame = out.render.frame;
  frame.world_from_rig = JitterPose(out.world_from_rig_true, scenario_.camera.slam, slam_rng_);
  frame.host_ticks = SlotTicks(scenario_.timing, out.slot);
  frame.sensor_ticks_ns = frame.host_ticks * 100;  // the device clock, in ns

  const Rigid3d ahat_from_world = world_from_ahat.Inverse();
  for (const Tool& tool : scene_.tools)
    out.ahat_from_tools.push_back(ahat_from_world * tool.scene_from_tool);
  for (const SceneObject& object : scene_.objects) {
    out.ahat_from_objects.push_back(ahat_from_world * object.scene_from_object);
  }
  for (const MarkerTruth& marker : out.render.markers) {
    out.marker_pixels.push_back(camera().Project(marker.centre_in_ahat));
  }
  out.marker_occluders = MarkerOccluders(scene_, out);
  return out;
}

std::vector<MarkerOccluder> MarkerOccluders(const Scene& scene, const SimulatedFrame& frame) {
  constexpr double kMarginMm = 1.0;  // a marker's own plate or skin lies within 0.1-0.5 mm
  const RenderResult& r = frame.render;
  std::vector<MarkerOccluder> occluders(r.markers.size());
  for (std::size_t m = 0; m < r.markers.size(); ++m) {
    const std::optional<Eigen::Vector2d>& uv = frame.marker_pixels[m];
    if (!uv) continue;
    const int u = static_cast<int>(std::lround(uv->x())),
              v = static_cast<int>(std::lround(uv->y()));
    if (!r.truth_range_mm.Contains(u, v) || r.truth_range_mm(u, v) <= 0.0f) continue;
    const MarkerTruth& marker = r.markers[m];
    const double radius_mm = 0.5 * scene.tools[static_cast<std::size_t>(marker.tool)]
                                       .markers[static_cast<std::size_t>(marker.marker)]
                                       .diameter_mm;
    if (r.truth_range_mm(u, v) >= marker.centre_in_ahat.norm() - radius_mm - kMarginMm) continue;
    if (r.truth_object(u, v) >= 0) {
      occluders[m].object = r.truth_object(u, v);
    } else if (const int id = r.truth_marker(u, v); id >= 0) {
      occluders[m].tool = r.markers[static_cast<std::size_t>(id)].tool;
    }
  }
  return occluders;
}
}  // namespace tofnav::sim
