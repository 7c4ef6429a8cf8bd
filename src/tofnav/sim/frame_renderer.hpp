// SPDX-License-Identifier: BSD-3-Clause
// Internal to render.cpp: the per-row passes of one frame and the buffers they share.
#pragma once

#include <complex>
#include <cstdint>

#include "tofnav/core/image.hpp"
#include "tofnav/sensor/ahat_camera.hpp"
#include "tofnav/sim/raycaster.hpp"
#include "tofnav/sim/render.hpp"

namespace tofnav::sim::internal {

/// Per-pixel ray model, built lazily per pixel and kept across frames: the exact centre ray and
/// the unit-plane Jacobian used for sub-rays, x(u + a, v + b) = x(u, v) + J (a, b).
struct PixelRays {
  enum State : std::uint8_t { kUnknown = 0, kLinear = 1, kCameraOnly = 2, kInvalid = 3 };
  Image<std::uint8_t> state;
  Image<Eigen::Vector3d> centre;    // unit ray of the integer pixel centre
  Image<Eigen::Vector2d> plane;     // unit-plane (x, y) of the centre
  Image<Eigen::Matrix2d> jacobian;  // d(x, y) / d(u, v) [1/px]
};

/// Images the passes of one frame share; reused across frames.
struct FrameBuffers {
  Image<std::complex<double>> phasor;  // Z of docs/tof_physics.md section 2 (AB counts)
  Image<std::complex<double>> scratch_wide;
  Image<std::complex<double>> scratch_narrow;
  Image<double> ab_noise;       // unit normal draws
  Image<double> depth_noise;    // unit normal draws, then correlated
  Image<std::uint8_t> lit;      // rendered and inside the illumination circle
  Image<double> solid_angle;    // of each pixel [sr], for multipath
  Image<double> diffuse_share;  // Lambertian part of the pixel's noise-free AB (0 .. 1)
};

/// The passes of one frame: CastRow (steps 1-3 and the noise draws) and FinishRow (5-7).
class FrameRenderer {
 public:
  FrameRenderer(const Scene& scene, const AhatCamera& camera, const SceneRaycaster& raycaster,
                const RenderOptions& options, const Eigen::Vector2d& principal_point_px,
                std::uint64_t seed);
  void CastRow(int v, PixelRays& rays, FrameBuffers& buffers, RenderResult& result) const;
  void FinishRow(int v, const FrameBuffers& buffers, RenderResult& result) const;

 private:
  struct Shading;
  Shading Shade(const RayHit& hit, const Eigen::Vector3d& ray, bool truth) const;
  bool PrepareRays(int u, int v, PixelRays& rays) const;
  Eigen::Vector3d SubRay(int u, int v, double a, double b, const PixelRays& rays) const;

  const Scene& scene_;
  const AhatCamera& camera_;
  const SceneRaycaster& raycaster_;
  const RenderOptions& options_;
  Eigen::Vector2d principal_point_px_;
  std::uint64_t seed_;
  double two_pi_over_alias_;
  double modulation_hz_;
};

}  // namespace tofnav::sim::internal
