// SPDX-License-Identifier: BSD-3-Clause
// The simulator's forward ToF model per hit and per pixel (docs/tof_physics.md sections 2-7).
#pragma once

#include <complex>

#include "tofnav/sim/material.hpp"

namespace tofnav::sim {

/// Which systematic range bias the hits carry.
enum class BiasMode {
  kNone,      // exact ranges (no subsurface delay, no intensity term, no f_rf)
  kPhysical,  // subsurface delay phasor + intensity term + f_rf on retro material
  kModel,     // the paper's C1 + C2 d + C3 theta per material (true d, theta) + f_rf on retro
};

/// Radiometry of the active illumination (docs/tof_physics.md section 3).
struct RadiometryOptions {
  double ab_scale = 65.0;           // K [counts m^2]: AB = K rho cos(theta) V / d^2, d in metres
  double falloff_power = 2.0;       // V = cos^p(off-axis angle), dimensionless
  double retro_baseline_mm = 15.0;  // illuminator-sensor baseline: observation angle atan(b / d)
  void Check() const;
};

/// Sensor constants and the pixel-level phase errors.
struct SensorOptions {
  double alias_mm = 1055.0;               // L = c / (2 f): phase wrap distance
  double illumination_radius_px = 256.0;  // outside this circle around the principal point: 4095
  double min_valid_ab = 10.0;             // measured AB below this: 4093
  double ab_clip = 65535.0;
  double wiggle_amplitude_mm = 1.0;  // cyclic error A sin(2 pi d / period + phase)
  double wiggle_period_mm = 1055.0 / 3.0;
  /// Rising from 420 to 595 mm; set by the materials plate's rows (docs/simulator.md 10).
  double wiggle_phase_rad = 3.5;
  double intensity_reference_ab = 130.0;  // AB_ref of the intensity bias term
  bool floor_depth = false;               // quantise by truncation instead of rounding
  double ModulationHz() const;
  void Check() const;
};

/// Random noise (docs/tof_physics.md section 4).
struct NoiseOptions {
  double ab_noise_scale = 1.0;      // sigma_AB = scale * sqrt(AB), dimensionless
  double depth_sigma_ref_mm = 1.0;  // sigma_d at AB = depth_sigma_ref_ab
  double depth_sigma_ref_ab = 130.0;
  double depth_sigma_floor_mm = 0.3;  // the floor at depth_sigma_floor_range_mm
  /// The floor grows with range as (range / depth_sigma_floor_range_mm)^depth_sigma_floor_exponent:
  /// a retro-reflector's pixels are so bright that the shot term gives them almost nothing, yet
  /// STTAR measured one marker pixel's depth sd rising from 0.49 mm at 350 mm to 1.08 mm at 700 mm
  /// (docs/simulator.md 10.1). 1.5 meets that row and STTAR's six tracking rows; 0 is the
  /// constant floor of sessions before 29.
  double depth_sigma_floor_range_mm = 350.0;
  double depth_sigma_floor_exponent = 1.5;
  double depth_correlation_px = 0.7;  // Gaussian blur of the white noise, renormalised; 0 = white
  void Check() const;
};

/// Noise-free AB a hit would give if it filled a whole pixel (docs/tof_physics.md section 3).
/// @param cos_incidence  -n . ray with the outward normal n: negative when the back is seen
/// @param cos_off_axis   z of the unit ray in `ahat`
double HitAmplitude(const Material& material, const RadiometryOptions& options, double range_mm,
                    double cos_incidence, double cos_off_axis);
/// The Lambertian part of HitAmplitude alone (the material's diffuse base, rho |cos theta|): what
/// a retro-reflector re-emits towards the camera of light that arrives from elsewhere than the
/// source (docs/simulator.md, multipath).
double DiffuseHitAmplitude(const Material& material, const RadiometryOptions& options,
                           double range_mm, double cos_incidence, double cos_off_axis);

/// Subsurface response multiplying exp(i 2 pi d / L): conj of H = (1 - a) + a / (1 + i w tau),
/// so its argument is >= 0 and the surface appears farther (the renderer applies it in physical
/// mode only).
std::complex<double> SubsurfaceFactor(const Material& material, double incidence_rad,
                                      double modulation_hz);
/// The range bias the subsurface factor causes: (L / 2 pi) arg [mm].
double SubsurfaceBiasMm(const Material& material, double incidence_rad,
                        const SensorOptions& sensor);

/// Additive range bias of one hit [mm]: model mode C1 + C2 d + C3 theta, physical mode the
/// intensity term gain * ln(AB_ref / hit_ab); plus f_rf(d) and the entrance-angle term
/// retro_angle_gain_mm_per_rad * incidence on retro material in both.
double AdditiveBiasMm(const Material& material, BiasMode mode, double range_mm,
                      double incidence_rad, double hit_ab, const SensorOptions& sensor);

/// sigma_d = max(floor, ref * sqrt(AB_ref / AB)) [mm]; infinite for AB <= 0.
double DepthNoiseSigmaMm(const NoiseOptions& options, double ab, double range_mm);

/// Cyclic error at observed range d [mm].
double WiggleMm(const SensorOptions& sensor, double range_mm);

}  // namespace tofnav::sim
