// SPDX-License-Identifier: BSD-3-Clause
// AHAT frame rendering: ray casting, forward ToF physics, noise, invalidation and ground truth.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <random>
#include <vector>

#include "tofnav/core/image.hpp"
#include "tofnav/core/rigid3d.hpp"
#include "tofnav/sensor/ahat_camera.hpp"
#include "tofnav/sensor/ahat_frame.hpp"
#include "tofnav/sim/image_filters.hpp"
#include "tofnav/sim/multipath.hpp"
#include "tofnav/sim/raycaster.hpp"
#include "tofnav/sim/scene.hpp"
#include "tofnav/sim/tof_model.hpp"

namespace tofnav::sim {

/// Lens scattering (docs/tof_physics.md 6.3): the complex range image is convolved with
/// (1 - wide - narrow) delta + wide G(wide_sigma) + narrow G(narrow_sigma).
struct ScatterOptions {
  /// epsilon_1, dimensionless; set by the materials plate's angle rows (docs/simulator.md 10).
  double wide_fraction = 1e-4;
  double wide_sigma_px = 30.0;
  double narrow_fraction = 1e-2;  // epsilon_2, dimensionless: the marker halo
  double narrow_sigma_px = 1.5;
  void Check() const;
};

/// Everything a render can switch. Defaults are the realistic ones of docs/simulator.md (physical
/// bias, noise, wiggle, scatter, one-bounce multipath) with 2 x 2 sub-rays for speed.
struct RenderOptions {
  int supersampling = 2;  // S: S x S sub-rays per pixel (4 for realism)
  bool jitter = true;     // random sub-ray position within each of the S x S strata
  /// Pixels outside the window are not rendered (code 4095, InvalidReason::kNotRendered). Light
  /// from outside the window does not scatter into it.
  PixelRect window = {0, 0, kAhatWidth, kAhatHeight};
  BiasMode bias_mode = BiasMode::kPhysical;
  RadiometryOptions radiometry;
  SensorOptions sensor;
  NoiseOptions noise;
  ScatterOptions scatter;
  MultipathOptions multipath;  // on by default (gain 1)
  void Check() const;
};

/// Every effect off: one centre ray per pixel, no bias, noise, wiggle or scatter. The depth is
/// then the exact radial range mod L rounded to 1 mm, and AB the noise-free amplitude.
RenderOptions IdealRenderOptions();
/// Model-consistent data (docs/simulator.md): model-mode bias, no wiggle and no multipath (both
/// outside Eq. (3)); noise and scatter on.
RenderOptions ModelConsistentRenderOptions();

/// Why a pixel's range code is invalid.
enum class InvalidReason : std::uint8_t {
  kValid = 0,
  kOutsideIllumination = 1,  // code 4095
  kLowSignal = 2,            // code 4093
  kNotRendered = 3,          // outside RenderOptions::window; code 4095
};
inline constexpr std::uint16_t kOutsideIlluminationCode = 4095;
inline constexpr std::uint16_t kLowSignalCode = 4093;

/// Truth about one marker of the scene in this frame.
struct MarkerTruth {
  int tool = 0;
  int marker = 0;
  int id = 0;                                                // Scene::MarkerId(tool, marker)
  Eigen::Vector3d centre_in_ahat = Eigen::Vector3d::Zero();  // sphere or disc centre [mm]
  int pixel_count = 0;  // pixels whose centre ray hits it first (0 = not visible)
};

/// A rendered frame and its ground truth. Truth images describe the centre ray of each pixel.
struct RenderResult {
  /// Raw sensor codes: valid range [mm] < 1055, 4093 low signal, 4095 outside the illumination
  /// (file writers map >= 4090 to 0, as real recordings do). world_from_rig treats the scene as
  /// the world: scene_from_ahat * inverse(rig_from_ahat).
  AhatFrame frame;
  Image<float> truth_range_mm;       // first-hit range; 0 = no hit or not rendered
  Image<float> truth_incidence_rad;  // arccos(|n . ray|)
  Image<Eigen::Vector3f> truth_normal_in_ahat;
  Image<float> truth_bias_mm;  // systematic bias of the centre hit alone (no noise, no mixing)
  Image<std::int16_t> truth_material;  // Scene::materials index, -1 none
  Image<std::int16_t> truth_object;    // Scene::objects index, -1 none
  Image<std::int32_t> truth_marker;    // Scene::MarkerId, -1 none
  Image<std::uint8_t> invalid_reason;  // InvalidReason
  std::vector<MarkerTruth> markers;    // every marker of the scene
};

namespace internal {
struct Workspace;
}  // namespace internal

/// Renders frames of one scene geometry; a new pose per frame only moves instances. Keeps the
/// per-pixel ray model and the frame buffers between frames.
class AhatRenderer {
 public:
  AhatRenderer(const Scene& scene, const AhatCamera& camera);
  ~AhatRenderer();
  AhatRenderer(AhatRenderer&&) noexcept;
  AhatRenderer& operator=(AhatRenderer&&) noexcept;

  /// Renders `scene` (same geometry as at construction, any poses) seen from scene_from_ahat.
  /// Draws one number from `rng`; every pixel gets its own stream derived from it, so the result
  /// is independent of the thread count and of the window.
  RenderResult Render(const Scene& scene, const Rigid3d& scene_from_ahat,
                      const RenderOptions& options, std::mt19937_64& rng);

 private:
  AhatCamera camera_;
  SceneRaycaster raycaster_;
  Eigen::Vector2d principal_point_px_ = Eigen::Vector2d::Zero();
  std::unique_ptr<internal::Workspace> workspace_;
};

/// One-shot render: builds an AhatRenderer and renders one frame.
RenderResult RenderAhatFrame(const Scene& scene, const AhatCamera& camera,
                             const Rigid3d& scene_from_ahat, const RenderOptions& options,
                             std::mt19937_64& rng);

}  // namespace tofnav::sim
