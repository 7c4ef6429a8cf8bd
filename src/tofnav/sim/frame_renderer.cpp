// SPDX-License-Identifier: BSD-3-Clause
// The per-row passes of one frame: ray casting and phasors, then AB, range, noise and codes.
#include "tofnav/sim/frame_renderer.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>
#include <tuple>
#include <utility>
#include <vector>

namespace tofnav::sim::internal {
namespace {

using Complex = std::complex<double>;

// SplitMix64 (Steele et al. 2014): a cheap stream per pixel seeded from (frame seed, pixel index).
class PixelRng {
 public:
  PixelRng(std::uint64_t frame_seed, std::uint64_t pixel)
      : state_(Mix(frame_seed ^ Mix(pixel + 0x632BE59BD9B4E019ull))) {}
  double Uniform() { return static_cast<double>(Next() >> 11) * 0x1.0p-53; }  // [0, 1)
  // Two independent standard normals (Marsaglia's polar method).
  std::pair<double, double> NormalPair() {
    for (;;) {
      const double x = 2.0 * Uniform() - 1.0, y = 2.0 * Uniform() - 1.0;
      const double s = x * x + y * y;
      if (s > 0.0 && s < 1.0) {
        const double f = std::sqrt(-2.0 * std::log(s) / s);
        return {f * x, f * y};
      }
    }
  }

 private:
  static std::uint64_t Mix(std::uint64_t z) {
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  std::uint64_t Next() { return Mix(state_ += 0x9E3779B97F4A7C15ull); }
  std::uint64_t state_;
};

// The Lambertian share of a pixel's return (1 where nothing retro-reflects).
double DiffuseShare(double diffuse, double total) { return total > 0.0 ? diffuse / total : 1.0; }

Eigen::Vector2d UnitPlane(const Eigen::Vector3d& ray) { return ray.head<2>() / ray.z(); }

// Sums amplitude * exp(i phase) * factor over the sub-rays of one pixel. Sub-rays on one surface
// differ in phase by a few mrad, so one sincos serves them all: the others rotate it by a
// Taylor series (7th order: error < 1e-13 for |delta| < 0.05 rad).
class PhasorSum {
 public:
  void Add(double amplitude, double phase_rad, const Complex& factor) {
    const double delta = phase_rad - base_phase_rad_;
    if (!has_base_ || std::abs(delta) > kMaxDeltaRad) {
      base_ = std::polar(1.0, phase_rad);
      base_phase_rad_ = phase_rad;
      has_base_ = true;
      sum_ += amplitude * base_ * factor;
      return;
    }
    const double d2 = delta * delta;
    const double c = 1.0 - d2 / 2.0 * (1.0 - d2 / 12.0 * (1.0 - d2 / 30.0));
    const double s = delta * (1.0 - d2 / 6.0 * (1.0 - d2 / 20.0 * (1.0 - d2 / 42.0)));
    sum_ += amplitude * (base_ * Complex(c, s)) * factor;
  }
  const Complex& sum() const { return sum_; }

 private:
  static constexpr double kMaxDeltaRad = 0.05;
  Complex sum_ = 0.0;
  Complex base_ = 1.0;
  double base_phase_rad_ = 0.0;
  bool has_base_ = false;
};

}  // namespace

struct FrameRenderer::Shading {
  double amplitude = 0.0;          // whole-pixel noise-free AB
  double diffuse_amplitude = 0.0;  // its Lambertian part (retro-reflection left out)
  double phase_range_mm = 0.0;     // range plus additive bias
  Complex factor = 1.0;            // subsurface response (physical mode)
  double incidence_rad = 0.0;      // computed only where needed
};

FrameRenderer::FrameRenderer(const Scene& scene, const AhatCamera& camera,
                             const SceneRaycaster& raycaster, const RenderOptions& options,
                             const Eigen::Vector2d& principal_point_px, std::uint64_t seed)
    : scene_(scene),
      camera_(camera),
      raycaster_(raycaster),
      options_(options),
      principal_point_px_(principal_point_px),
      seed_(seed),
      two_pi_over_alias_(2.0 * std::numbers::pi / options.sensor.alias_mm),
      modulation_hz_(options.sensor.ModulationHz()) {}

FrameRenderer::Shading FrameRenderer::Shade(const RayHit& hit, const Eigen::Vector3d& ray,
                                            bool truth) const {
  const Material& material = scene_.materials[static_cast<std::size_t>(hit.material)];
  const BiasMode mode = options_.bias_mode;
  const bool subsurface = mode == BiasMode::kPhysical && material.subsurface_fraction > 0.0;
  const bool need_incidence =
      truth || (mode == BiasMode::kModel && material.model_c3_mm_per_rad != 0.0) ||
      (subsurface && material.subsurface_angle_gain_per_rad != 0.0) ||
      (material.retro_reflective && material.retro_angle_gain_mm_per_rad != 0.0);
  Shading s;
  const double cos_incidence = -hit.normal_in_ahat.dot(ray);
  if (need_incidence) s.incidence_rad = std::acos(std::min(1.0, std::abs(cos_incidence)));
  s.amplitude = HitAmplitude(material, options_.radiometry, hit.range_mm, cos_incidence, ray.z());
  s.diffuse_amplitude =
      material.retro_reflective
          ? DiffuseHitAmplitude(material, options_.radiometry, hit.range_mm, cos_incidence, ray.z())
          : s.amplitude;
  s.phase_range_mm = hit.range_mm + AdditiveBiasMm(material, mode, hit.range_mm, s.incidence_rad,
                                                   s.amplitude, options_.sensor);
  if (subsurface) s.factor = SubsurfaceFactor(material, s.incidence_rad, modulation_hz_);
  return s;
}

bool FrameRenderer::PrepareRays(int u, int v, PixelRays& rays) const {
  std::uint8_t& state = rays.state(u, v);
  if (state == PixelRays::kUnknown) {
    const std::optional<Eigen::Vector3d> centre = camera_.Ray({u, v});
    state = centre ? PixelRays::kCameraOnly : PixelRays::kInvalid;
    if (centre) {
      rays.centre(u, v) = *centre;
      rays.plane(u, v) = UnitPlane(*centre);
      const auto ray_at = [&](double du, double dv) { return camera_.Ray({u + du, v + dv}); };
      const auto right = ray_at(0.5, 0.0), left = ray_at(-0.5, 0.0);
      const auto down = ray_at(0.0, 0.5), up = ray_at(0.0, -0.5);
      if (right && left && down && up) {
        rays.jacobian(u, v).col(0) = UnitPlane(*right) - UnitPlane(*left);
        rays.jacobian(u, v).col(1) = UnitPlane(*down) - UnitPlane(*up);
        state = PixelRays::kLinear;
      }
    }
  }
  return state != PixelRays::kInvalid;
}

Eigen::Vector3d FrameRenderer::SubRay(int u, int v, double a, double b,
                                      const PixelRays& rays) const {
  if (rays.state(u, v) == PixelRays::kLinear) {
    // The camera interpolates its table bilinearly; within one pixel that is linear to 1e-5 rad.
    const Eigen::Vector2d xy = rays.plane(u, v) + rays.jacobian(u, v) * Eigen::Vector2d(a, b);
    const double z = 1.0 / std::sqrt(xy.squaredNorm() + 1.0);
    return {z * xy.x(), z * xy.y(), z};
  }
  const std::optional<Eigen::Vector3d> ray = camera_.Ray({u + a, v + b});
  return ray ? *ray : rays.centre(u, v);  // at the edge of the table: the pixel's centre ray
}

void FrameRenderer::CastRow(int v, PixelRays& pixel_rays, FrameBuffers& buffers,
                            RenderResult& result) const {
  const PixelRect& window = options_.window;
  const int s = options_.supersampling;
  const bool centre_only = s == 1 && !options_.jitter;
  const std::size_t rays_per_pixel = centre_only ? 1 : 1 + static_cast<std::size_t>(s * s);
  const double inv_s = 1.0 / s;
  const bool draw_noise = options_.noise.ab_noise_scale > 0.0 ||
                          options_.noise.depth_sigma_ref_mm > 0.0 ||
                          options_.noise.depth_sigma_floor_mm > 0.0;
  const double radius2 =
      options_.sensor.illumination_radius_px * options_.sensor.illumination_radius_px;
  thread_local std::vector<Eigen::Vector3d> rays;
  thread_local std::vector<RayHit> hits;
  thread_local std::vector<int> pixels;
  rays.clear();
  pixels.clear();
  for (int u = window.u0; u < window.u0 + window.width; ++u) {
    buffers.phasor(u, v) = 0.0;
    buffers.diffuse_share(u, v) = 1.0;
    buffers.ab_noise(u, v) = buffers.depth_noise(u, v) = 0.0;
    const double du = u - principal_point_px_.x(), dv = v - principal_point_px_.y();
    const bool lit =
        camera_.IsValid(u, v) && du * du + dv * dv <= radius2 && PrepareRays(u, v, pixel_rays);
    buffers.lit(u, v) = lit ? 1 : 0;
    result.invalid_reason(u, v) = static_cast<std::uint8_t>(
        lit ? InvalidReason::kValid : InvalidReason::kOutsideIllumination);
    if (!lit) continue;
    pixels.push_back(u);
    rays.push_back(pixel_rays.centre(u, v));
    PixelRng rng(seed_, static_cast<std::uint64_t>(v) * kAhatWidth + static_cast<std::uint64_t>(u));
    for (int j = 0; j < s && !centre_only; ++j) {
      for (int i = 0; i < s; ++i) {
        const double jx = options_.jitter ? rng.Uniform() : 0.5;
        const double jy = options_.jitter ? rng.Uniform() : 0.5;
        rays.push_back(SubRay(u, v, (i + jx) * inv_s - 0.5, (j + jy) * inv_s - 0.5, pixel_rays));
      }
    }
    if (draw_noise) std::tie(buffers.ab_noise(u, v), buffers.depth_noise(u, v)) = rng.NormalPair();
  }
  hits.resize(rays.size());
  raycaster_.Intersect(rays, hits);
  const double weight = 1.0 / static_cast<double>(rays_per_pixel - (centre_only ? 0 : 1));
  for (std::size_t p = 0; p < pixels.size(); ++p) {
    const int u = pixels[p];
    const std::size_t first = p * rays_per_pixel;
    const RayHit& centre = hits[first];
    if (centre.hit()) {  // ground truth of the centre ray
      const Shading shading = Shade(centre, rays[first], true);
      if (centre_only) {
        buffers.phasor(u, v) =
            std::polar(shading.amplitude, two_pi_over_alias_ * shading.phase_range_mm) *
            shading.factor;
        buffers.diffuse_share(u, v) = DiffuseShare(shading.diffuse_amplitude, shading.amplitude);
      }
      result.truth_range_mm(u, v) = static_cast<float>(centre.range_mm);
      result.truth_incidence_rad(u, v) = static_cast<float>(shading.incidence_rad);
      result.truth_normal_in_ahat(u, v) = centre.normal_in_ahat.cast<float>();
      result.truth_bias_mm(u, v) = static_cast<float>(
          shading.phase_range_mm - centre.range_mm + std::arg(shading.factor) / two_pi_over_alias_);
      result.truth_material(u, v) = static_cast<std::int16_t>(centre.material);
      result.truth_object(u, v) = static_cast<std::int16_t>(centre.object);
      if (centre.marker >= 0) {
        result.truth_marker(u, v) = scene_.MarkerId(centre.tool, centre.marker);
      }
    }
    if (centre_only) continue;
    PhasorSum sum;
    double amplitude_sum = 0.0, diffuse_sum = 0.0;
    for (std::size_t k = first + 1; k < first + rays_per_pixel; ++k) {
      if (!hits[k].hit()) continue;
      const Shading shading = Shade(hits[k], rays[k], false);
      sum.Add(shading.amplitude, two_pi_over_alias_ * shading.phase_range_mm, shading.factor);
      amplitude_sum += shading.amplitude;
      diffuse_sum += shading.diffuse_amplitude;
    }
    buffers.phasor(u, v) = weight * sum.sum();
    buffers.diffuse_share(u, v) = DiffuseShare(diffuse_sum, amplitude_sum);
  }
}

void FrameRenderer::FinishRow(int v, const FrameBuffers& buffers, RenderResult& result) const {
  const SensorOptions& sensor = options_.sensor;
  const NoiseOptions& noise = options_.noise;
  const PixelRect& window = options_.window;
  for (int u = window.u0; u < window.u0 + window.width; ++u) {
    if (!buffers.lit(u, v)) continue;
    const Complex z = buffers.phasor(u, v);
    const double ab_true = std::sqrt(std::norm(z));
    // Step 5: AB = |Z| plus shot-like noise, clipped and quantised.
    const double ab =
        std::clamp(ab_true + noise.ab_noise_scale * std::sqrt(ab_true) * buffers.ab_noise(u, v),
                   0.0, sensor.ab_clip);
    const auto ab_code = static_cast<std::uint16_t>(std::lround(ab));
    result.frame.ab(u, v) = ab_code;
    // Step 7: low-signal invalidation (the illumination circle was applied when casting).
    if (ab_code < sensor.min_valid_ab) {
      result.frame.range_mm(u, v) = kLowSignalCode;
      result.invalid_reason(u, v) = static_cast<std::uint8_t>(InvalidReason::kLowSignal);
      continue;
    }
    // Step 6: phase to range mod L, then wiggle and AB-dependent noise.
    double range_mm = std::arg(z) / two_pi_over_alias_;
    range_mm += WiggleMm(sensor, range_mm);
    // arg() is in (-pi, pi]: the floor's range is the wrapped one, in [0, alias).
    const double sigma_mm =
        DepthNoiseSigmaMm(noise, ab_true, range_mm < 0.0 ? range_mm + sensor.alias_mm : range_mm);
    if (std::isfinite(sigma_mm)) range_mm += sigma_mm * buffers.depth_noise(u, v);
    range_mm = std::fmod(range_mm, sensor.alias_mm);
    if (range_mm < 0.0) range_mm += sensor.alias_mm;
    // Step 7, quantisation to 1 mm.
    double quantised = sensor.floor_depth ? std::floor(range_mm) : std::round(range_mm);
    if (quantised >= sensor.alias_mm) quantised = 0.0;  // rounded up onto the wrap point
    result.frame.range_mm(u, v) = static_cast<std::uint16_t>(quantised);
  }
}

}  // namespace tofnav::sim::internal
