// SPDX-License-Identifier: BSD-3-Clause
// AHAT frame rendering, the per-frame pipeline of docs/tof_physics.md section 2.
#include "tofnav/sim/render.hpp"

#include <algorithm>
#include <optional>

#include "tofnav/core/parallel_for.hpp"
#include "tofnav/core/require.hpp"
#include "tofnav/sim/frame_renderer.hpp"

namespace tofnav::sim {
namespace internal {

struct Workspace {
  PixelRays rays;
  FrameBuffers buffers;
};

}  // namespace internal
namespace {

using Complex = std::complex<double>;

RenderResult EmptyResult() {
  constexpr int w = kAhatWidth, h = kAhatHeight;
  RenderResult r;
  r.frame.range_mm = Image<std::uint16_t>(w, h, kOutsideIlluminationCode);
  r.frame.ab = Image<std::uint16_t>(w, h, 0);
  r.truth_range_mm = Image<float>(w, h, 0.0f);
  r.truth_incidence_rad = Image<float>(w, h, 0.0f);
  r.truth_normal_in_ahat = Image<Eigen::Vector3f>(w, h, Eigen::Vector3f::Zero());
  r.truth_bias_mm = Image<float>(w, h, 0.0f);
  r.truth_material = Image<std::int16_t>(w, h, -1);
  r.truth_object = Image<std::int16_t>(w, h, -1);
  r.truth_marker = Image<std::int32_t>(w, h, -1);
  r.invalid_reason =
      Image<std::uint8_t>(w, h, static_cast<std::uint8_t>(InvalidReason::kNotRendered));
  return r;
}

void CopyRect(const Image<Complex>& from, Image<Complex>& to, const PixelRect& rect) {
  ParallelFor(rect.v0, rect.v0 + rect.height, [&](std::int64_t row) {
    const int v = static_cast<int>(row);
    std::copy_n(&from(rect.u0, v), rect.width, &to(rect.u0, v));
  });
}

// Step 4: complex PSF (1 - e1 - e2) delta + e1 G_wide + e2 G_narrow over the window.
void ApplyLensScatter(const ScatterOptions& scatter, const PixelRect& window,
                      internal::FrameBuffers& buffers) {
  const bool wide = scatter.wide_fraction > 0.0, narrow = scatter.narrow_fraction > 0.0;
  if (!wide && !narrow) return;
  if (wide) {
    CopyRect(buffers.phasor, buffers.scratch_wide, window);
    if (scatter.wide_sigma_px >= 3.0) {
      BoxGaussianBlur(buffers.scratch_wide, window, scatter.wide_sigma_px);
    } else {
      GaussianBlur(buffers.scratch_wide, window, scatter.wide_sigma_px);
    }
  }
  if (narrow) {
    CopyRect(buffers.phasor, buffers.scratch_narrow, window);
    GaussianBlur(buffers.scratch_narrow, window, scatter.narrow_sigma_px);
  }
  const double direct = 1.0 - scatter.wide_fraction - scatter.narrow_fraction;
  ParallelFor(window.v0, window.v0 + window.height, [&](std::int64_t row) {
    const int v = static_cast<int>(row);
    for (int u = window.u0; u < window.u0 + window.width; ++u) {
      Complex value = direct * buffers.phasor(u, v);
      if (wide) value += scatter.wide_fraction * buffers.scratch_wide(u, v);
      if (narrow) value += scatter.narrow_fraction * buffers.scratch_narrow(u, v);
      buffers.phasor(u, v) = value;
    }
  });
}

// Step 3: one-bounce multipath from the centre-ray truth of this frame.
void ApplyMultipath(const RenderOptions& options, const Scene& scene, const RenderResult& result,
                    internal::Workspace& workspace) {
  if (options.multipath.gain <= 0.0) return;
  const PixelRect& window = options.window;
  const internal::PixelRays& rays = workspace.rays;
  Image<double>& solid_angle = workspace.buffers.solid_angle;
  ParallelFor(window.v0, window.v0 + window.height, [&](std::int64_t row) {
    const int v = static_cast<int>(row);
    for (int u = window.u0; u < window.u0 + window.width; ++u) {
      // d Omega = dx dy / (1 + x^2 + y^2)^(3/2) on the unit plane z = 1.
      const bool linear = rays.state(u, v) == internal::PixelRays::kLinear;
      const double rho2 = 1.0 + rays.plane(u, v).squaredNorm();
      solid_angle(u, v) =
          linear ? std::abs(rays.jacobian(u, v).determinant()) / (rho2 * std::sqrt(rho2)) : 0.0;
    }
  });
  const MultipathInputs in{
      result.truth_range_mm,
      result.truth_normal_in_ahat,
      result.truth_material,
      result.truth_object,
      rays.centre,
      solid_angle,
      workspace.buffers.diffuse_share,
      options.bias_mode == BiasMode::kPhysical ? options.sensor.ModulationHz() : 0.0};
  AddMultipath(options.multipath, scene, window, in, options.sensor.alias_mm,
               workspace.buffers.phasor);
}

// Correlated depth noise: blurred white noise renormalised to unit standard deviation.
void CorrelateDepthNoise(const NoiseOptions& noise, const PixelRect& window, Image<double>& draws) {
  if (noise.depth_correlation_px <= 0.0) return;
  GaussianBlur(draws, window, noise.depth_correlation_px);
  const double gain = GaussianNoiseGain(noise.depth_correlation_px);
  ParallelFor(window.v0, window.v0 + window.height, [&](std::int64_t row) {
    const int v = static_cast<int>(row);
    for (int u = window.u0; u < window.u0 + window.width; ++u) draws(u, v) /= gain;
  });
}

}  // namespace

void ScatterOptions::Check() const {
  Require(wide_fraction >= 0.0 && narrow_fraction >= 0.0 && wide_fraction + narrow_fraction < 1.0,
          "ScatterOptions: fractions must be >= 0 and sum to < 1");
  Require(wide_sigma_px > 0.0 && narrow_sigma_px > 0.0, "ScatterOptions: sigmas must be > 0");
}

void RenderOptions::Check() const {
  Require(supersampling >= 1 && supersampling <= 16,
          "RenderOptions.supersampling must lie in [1, 16]");
  Require(window.width >= 0 && window.height >= 0 && window.u0 >= 0 && window.v0 >= 0 &&
              window.u0 + window.width <= kAhatWidth && window.v0 + window.height <= kAhatHeight,
          "RenderOptions.window must lie inside the 512 x 512 image");
  radiometry.Check();
  sensor.Check();
  noise.Check();
  scatter.Check();
  multipath.Check();
}

RenderOptions IdealRenderOptions() {
  RenderOptions options;
  options.supersampling = 1;
  options.jitter = false;
  options.bias_mode = BiasMode::kNone;
  options.sensor.wiggle_amplitude_mm = 0.0;
  options.noise.ab_noise_scale = 0.0;
  options.noise.depth_sigma_ref_mm = 0.0;
  options.noise.depth_sigma_floor_mm = 0.0;
  options.scatter.wide_fraction = 0.0;
  options.scatter.narrow_fraction = 0.0;
  options.multipath.gain = 0.0;
  return options;
}

RenderOptions ModelConsistentRenderOptions() {
  RenderOptions options;
  options.bias_mode = BiasMode::kModel;
  options.sensor.wiggle_amplitude_mm = 0.0;
  options.multipath.gain = 0.0;
  return options;
}

AhatRenderer::AhatRenderer(const Scene& scene, const AhatCamera& camera)
    : camera_(camera), raycaster_(scene), workspace_(std::make_unique<internal::Workspace>()) {
  Require(camera.width() == kAhatWidth && camera.height() == kAhatHeight,
          "AhatRenderer: the camera must be 512 x 512");
  const std::optional<Eigen::Vector2d> principal = camera.Project(Eigen::Vector3d::UnitZ());
  Require(principal.has_value(), "AhatRenderer: the optical axis does not project into the image");
  principal_point_px_ = *principal;
  constexpr int w = kAhatWidth, h = kAhatHeight;
  internal::PixelRays& rays = workspace_->rays;
  rays.state = Image<std::uint8_t>(w, h, internal::PixelRays::kUnknown);
  rays.centre = Image<Eigen::Vector3d>(w, h, Eigen::Vector3d::Zero());
  rays.plane = Image<Eigen::Vector2d>(w, h, Eigen::Vector2d::Zero());
  rays.jacobian = Image<Eigen::Matrix2d>(w, h, Eigen::Matrix2d::Zero());
  internal::FrameBuffers& b = workspace_->buffers;
  b.phasor = b.scratch_wide = b.scratch_narrow = Image<Complex>(w, h);
  b.ab_noise = b.depth_noise = b.solid_angle = b.diffuse_share = Image<double>(w, h);
  b.lit = Image<std::uint8_t>(w, h, 0);
}

AhatRenderer::~AhatRenderer() = default;
AhatRenderer::AhatRenderer(AhatRenderer&&) noexcept = default;
AhatRenderer& AhatRenderer::operator=(AhatRenderer&&) noexcept = default;

RenderResult AhatRenderer::Render(const Scene& scene, const Rigid3d& scene_from_ahat,
                                  const RenderOptions& options, std::mt19937_64& rng) {
  options.Check();
  raycaster_.SetPoses(scene, scene_from_ahat);
  RenderResult result = EmptyResult();
  internal::FrameBuffers& buffers = workspace_->buffers;
  const internal::FrameRenderer frame(scene, camera_, raycaster_, options, principal_point_px_,
                                      rng());
  const PixelRect& window = options.window;
  // Steps 1-3: ray casting, a phasor per hit, sum of sub-ray phasors; the noise draws.
  ParallelFor(window.v0, window.v0 + window.height, [&](std::int64_t v) {
    frame.CastRow(static_cast<int>(v), workspace_->rays, buffers, result);
  });
  ApplyMultipath(options, scene, result, *workspace_);  // step 3
  ApplyLensScatter(options.scatter, window, buffers);   // step 4
  CorrelateDepthNoise(options.noise, window, buffers.depth_noise);
  // Steps 5-7: AB, range, noise, wiggle, invalidation, quantisation.
  ParallelFor(window.v0, window.v0 + window.height,
              [&](std::int64_t v) { frame.FinishRow(static_cast<int>(v), buffers, result); });

  const Rigid3d ahat_from_scene = scene_from_ahat.Inverse();
  for (int t = 0; t < static_cast<int>(scene.tools.size()); ++t) {
    const Tool& tool = scene.tools[static_cast<std::size_t>(t)];
    for (int m = 0; m < static_cast<int>(tool.markers.size()); ++m) {
      const Eigen::Vector3d& centre = tool.markers[static_cast<std::size_t>(m)].centre_in_tool;
      result.markers.push_back(
          {t, m, scene.MarkerId(t, m), ahat_from_scene * (tool.scene_from_tool * centre), 0});
    }
  }
  for (int v = window.v0; v < window.v0 + window.height; ++v) {
    for (int u = window.u0; u < window.u0 + window.width; ++u) {
      const std::int32_t id = result.truth_marker(u, v);
      if (id >= 0) ++result.markers[static_cast<std::size_t>(id)].pixel_count;
    }
  }
  result.frame.world_from_rig = scene_from_ahat * camera_.rig_from_ahat().Inverse();
  return result;
}

RenderResult RenderAhatFrame(const Scene& scene, const AhatCamera& camera,
                             const Rigid3d& scene_from_ahat, const RenderOptions& options,
                             std::mt19937_64& rng) {
  AhatRenderer renderer(scene, camera);
  return renderer.Render(scene, scene_from_ahat, options, rng);
}

}  // namespace tofnav::sim
