// SPDX-License-Identifier: BSD-3-Clause
// Surface materials of the AHAT simulator: albedo, subsurface delay, retro-reflection, model mode.
#pragma once

#include <string>

namespace tofnav::sim {

/// Shape of the retro-reflector range bias f_rf(d) (docs/tof_physics.md section 5.3). Each curve
/// spans 0 .. amplitude over 300 .. 700 mm and is extended linearly outside.
enum class RetroCurve { kNone, kLinear, kQuadratic, kSigmoid, kWavy };

/// Optical and ToF response of one surface material at 850 nm / 142.1 MHz.
struct Material {
  std::string name;
  double albedo = 0.5;  // rho, dimensionless Lambertian reflectance (0 .. 1)

  // Physical mode (docs/tof_physics.md section 5.1): the return is an instantaneous fraction plus
  // an exponentially delayed one, H = (1 - a) + a / (1 + i w tau), a(theta) = a0 (1 + k theta).
  double subsurface_fraction = 0.0;            // a0, dimensionless (0 .. 1)
  double subsurface_delay_ps = 0.0;            // tau [ps]
  double subsurface_angle_gain_per_rad = 0.0;  // k_theta [1/rad]; a(theta) is clamped to [0, 1]
  /// Intensity-related phase error (Lindner et al. 2010): bias = gain * ln(AB_ref / AB_hit) [mm],
  /// with AB_hit the noise-free AB the hit would give over a whole pixel. It makes the physical
  /// bias grow with range and incidence in a shape that is not the paper's C1 + C2 d + C3 theta.
  double intensity_bias_gain_mm = 0.0;

  // Model mode (paper Eq. (3)): bias = C1 + C2 d + C3 theta with the true range and incidence.
  double model_c1_mm = 0.0;
  double model_c2 = 0.0;  // dimensionless: mm of bias per mm of range
  double model_c3_mm_per_rad = 0.0;

  // Retro-reflective sheeting (docs/tof_physics.md section 3):
  // AB = K pi R_A0 exp(-alpha / alpha0) cos(beta) V / d^2 for entrance angles beta < cut-off.
  bool retro_reflective = false;
  double retro_coefficient = 300.0;                 // R_A0 [cd lx^-1 m^-2]
  double retro_observation_falloff_rad = 0.017453;  // alpha0 (1 degree)
  double retro_entrance_cutoff_rad = 0.95993;  // beta beyond which retro-reflection stops (55 deg)
  RetroCurve retro_curve = RetroCurve::kLinear;  // f_rf(d), added to the range of retro hits
  double retro_curve_amplitude_mm = 4.0;         // f_rf span over 300 .. 700 mm
  /// The sheeting's range error grows with the entrance angle beta: + gain * beta [mm/rad]. The
  /// light's path inside the prisms lengthens as the sheeting tilts; the linear stage saw 1.08 mm
  /// between its 0-30 deg runs on average (docs/simulator.md 10). Added in both bias modes.
  double retro_angle_gain_mm_per_rad = 0.0;

  /// Throws std::invalid_argument (PreconditionError) naming the bad field.
  void Check() const;
};

/// Skin: rho 0.55, about +7.5 mm subsurface bias (paper: 7.58 +- 1.49 mm).
Material SkinMaterial();
/// 3D-printing materials of the paper's phantoms (docs/tof_physics.md section 5.2 magnitudes).
Material NylonMaterial();
Material PhotopolymerMaterial();
Material PlaMaterial();
/// Black PC-ABS: rho 0.05, so low AB, high noise and dropouts (the paper's "unstable" material).
Material PcAbsMaterial();
/// Retro-reflective tape or sphere coating with the given f_rf(d) shape.
Material RetroReflectiveMaterial(RetroCurve curve = RetroCurve::kLinear);
/// A plain Lambertian surface with no systematic bias (walls, tables, test boards).
Material DiffuseMaterial(double albedo);
/// A surgical drape (non-woven cloth): Lambertian, rho 0.5 at 850 nm (an assumption: drape dyes
/// absorb in the visible, not in the near infrared), no systematic bias.
Material DrapeMaterial();

/// f_rf(d) [mm] of the given shape and amplitude at range `range_mm`.
double RetroRangeBiasMm(RetroCurve curve, double amplitude_mm, double range_mm);

}  // namespace tofnav::sim
