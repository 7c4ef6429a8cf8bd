// SPDX-License-Identifier: BSD-3-Clause
// The simulator's forward ToF model per hit and per pixel.
#include "tofnav/sim/tof_model.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "tofnav/core/require.hpp"

namespace tofnav::sim {
namespace {

constexpr double kSpeedOfLightMmPerS = 299792458e3;
constexpr double kMmPerM = 1000.0;
constexpr double kSecondsPerPs = 1e-12;

// AB per unit reflectance at this range and off-axis angle: K cos^p(off-axis) / d^2.
double RadiometricScale(const RadiometryOptions& options, double range_mm, double cos_off_axis) {
  const double range_m = range_mm / kMmPerM;
  const double c = std::max(cos_off_axis, 0.0);
  const double falloff = options.falloff_power == 2.0 ? c * c : std::pow(c, options.falloff_power);
  return options.ab_scale * falloff / (range_m * range_m);
}

}  // namespace

void RadiometryOptions::Check() const {
  Require(ab_scale > 0.0, "RadiometryOptions.ab_scale must be > 0");
  Require(falloff_power >= 0.0, "RadiometryOptions.falloff_power must be >= 0");
  Require(retro_baseline_mm >= 0.0, "RadiometryOptions.retro_baseline_mm must be >= 0");
}

double SensorOptions::ModulationHz() const { return kSpeedOfLightMmPerS / (2.0 * alias_mm); }

void SensorOptions::Check() const {
  Require(alias_mm > 0.0, "SensorOptions.alias_mm must be > 0");
  Require(illumination_radius_px > 0.0, "SensorOptions.illumination_radius_px must be > 0");
  Require(min_valid_ab >= 0.0, "SensorOptions.min_valid_ab must be >= 0");
  Require(ab_clip > 0.0 && ab_clip <= 65535.0, "SensorOptions.ab_clip must lie in (0, 65535]");
  Require(wiggle_amplitude_mm >= 0.0, "SensorOptions.wiggle_amplitude_mm must be >= 0");
  Require(wiggle_period_mm > 0.0, "SensorOptions.wiggle_period_mm must be > 0");
  Require(intensity_reference_ab > 0.0, "SensorOptions.intensity_reference_ab must be > 0");
}

void NoiseOptions::Check() const {
  Require(ab_noise_scale >= 0.0, "NoiseOptions.ab_noise_scale must be >= 0");
  Require(depth_sigma_ref_mm >= 0.0, "NoiseOptions.depth_sigma_ref_mm must be >= 0");
  Require(depth_sigma_ref_ab > 0.0, "NoiseOptions.depth_sigma_ref_ab must be > 0");
  Require(depth_sigma_floor_mm >= 0.0, "NoiseOptions.depth_sigma_floor_mm must be >= 0");
  Require(depth_sigma_floor_range_mm > 0.0 && std::isfinite(depth_sigma_floor_range_mm),
          "NoiseOptions.depth_sigma_floor_range_mm must be > 0");
  Require(depth_sigma_floor_exponent >= 0.0 && depth_sigma_floor_exponent <= 4.0,
          "NoiseOptions.depth_sigma_floor_exponent must be in [0, 4]");
  Require(depth_correlation_px >= 0.0 && depth_correlation_px <= 5.0,
          "NoiseOptions.depth_correlation_px must lie in [0, 5]");
}

double DiffuseHitAmplitude(const Material& material, const RadiometryOptions& options,
                           double range_mm, double cos_incidence, double cos_off_axis) {
  // Lambertian: rho cos(theta)
  return RadiometricScale(options, range_mm, cos_off_axis) * material.albedo *
         std::abs(cos_incidence);
}

double HitAmplitude(const Material& material, const RadiometryOptions& options, double range_mm,
                    double cos_incidence, double cos_off_axis) {
  const double scale = RadiometricScale(options, range_mm, cos_off_axis);
  double reflectance = material.albedo * std::abs(cos_incidence);  // Lambertian: rho cos(theta)
  if (material.retro_reflective && cos_incidence > std::cos(material.retro_entrance_cutoff_rad)) {
    // R_A(alpha, beta) = R_A0 exp(-alpha / alpha0) cos(beta); AB_rr = K pi R_A V / d^2.
    const double observation_rad = std::atan(options.retro_baseline_mm / range_mm);
    reflectance += std::numbers::pi * material.retro_coefficient *
                   std::exp(-observation_rad / material.retro_observation_falloff_rad) *
                   cos_incidence;
  }
  return scale * reflectance;
}

std::complex<double> SubsurfaceFactor(const Material& material, double incidence_rad,
                                      double modulation_hz) {
  const double fraction = std::clamp(
      material.subsurface_fraction * (1.0 + material.subsurface_angle_gain_per_rad * incidence_rad),
      0.0, 1.0);
  const double omega_tau =
      2.0 * std::numbers::pi * modulation_hz * material.subsurface_delay_ps * kSecondsPerPs;
  // H = (1 - a) + a / (1 + i w tau) with e^{-i w t} for a delay t; our phasors use e^{+i 2 pi d /
  // L}.
  const std::complex<double> h = (1.0 - fraction) + fraction / std::complex<double>(1.0, omega_tau);
  return std::conj(h);
}

double SubsurfaceBiasMm(const Material& material, double incidence_rad,
                        const SensorOptions& sensor) {
  const std::complex<double> factor =
      SubsurfaceFactor(material, incidence_rad, sensor.ModulationHz());
  return sensor.alias_mm / (2.0 * std::numbers::pi) * std::arg(factor);
}

double AdditiveBiasMm(const Material& material, BiasMode mode, double range_mm,
                      double incidence_rad, double hit_ab, const SensorOptions& sensor) {
  double bias_mm = 0.0;
  if (mode == BiasMode::kNone) return bias_mm;
  if (mode == BiasMode::kModel) {
    bias_mm += material.model_c1_mm + material.model_c2 * range_mm +
               material.model_c3_mm_per_rad * incidence_rad;  // paper Eq. (3)
  } else if (material.intensity_bias_gain_mm != 0.0 && hit_ab > 0.0) {
    bias_mm += material.intensity_bias_gain_mm * std::log(sensor.intensity_reference_ab / hit_ab);
  }
  if (material.retro_reflective) {
    bias_mm += RetroRangeBiasMm(material.retro_curve, material.retro_curve_amplitude_mm, range_mm) +
               material.retro_angle_gain_mm_per_rad * incidence_rad;
  }
  return bias_mm;
}

double DepthNoiseSigmaMm(const NoiseOptions& options, double ab, double range_mm) {
  if (!(ab > 0.0)) return std::numeric_limits<double>::infinity();
  const double floor_mm =
      options.depth_sigma_floor_exponent == 0.0
          ? options.depth_sigma_floor_mm
          : options.depth_sigma_floor_mm *
                std::pow(std::max(range_mm, 1.0) / options.depth_sigma_floor_range_mm,
                         options.depth_sigma_floor_exponent);
  return std::max(floor_mm,
                  options.depth_sigma_ref_mm * std::sqrt(options.depth_sigma_ref_ab / ab));
}

double WiggleMm(const SensorOptions& sensor, double range_mm) {
  if (sensor.wiggle_amplitude_mm == 0.0) return 0.0;
  return sensor.wiggle_amplitude_mm *
         std::sin(2.0 * std::numbers::pi * range_mm / sensor.wiggle_period_mm +
                  sensor.wiggle_phase_rad);
}

}  // namespace tofnav::sim
