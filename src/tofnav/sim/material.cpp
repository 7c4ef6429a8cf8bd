// SPDX-License-Identifier: BSD-3-Clause
// Material presets and the retro-reflector range bias curves.
#include "tofnav/sim/material.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <utility>

#include "tofnav/core/require.hpp"

namespace tofnav::sim {
namespace {

constexpr double kCurveStartMm = 300.0;  // f_rf is specified over 300 .. 700 mm (paper)
constexpr double kCurveEndMm = 700.0;
constexpr double kCurveSpanMm = 4.0;  // the tabulated curves span 0 .. 4 mm

// The tabulated 4 mm curves of docs/tof_physics.md section 5.3, valid inside [300, 700] mm.
double UnitCurveMm(RetroCurve curve, double d_mm) {
  switch (curve) {
    case RetroCurve::kNone:
      return 0.0;
    case RetroCurve::kLinear:
      return 4.0 * (d_mm - 300.0) / 400.0;
    case RetroCurve::kQuadratic: {
      const double x = (d_mm - 300.0) / 400.0;
      return 4.0 * x * x;
    }
    case RetroCurve::kSigmoid:
      return 4.0 / (1.0 + std::exp(-(d_mm - 500.0) / 40.0));
    case RetroCurve::kWavy:
      return 2.0 + 1.5 * std::sin(2.0 * std::numbers::pi * (d_mm - 300.0) / 352.0) +
             0.5 * (d_mm - 500.0) / 200.0;
  }
  return 0.0;
}

Material Subsurface(std::string name, double albedo, double fraction, double delay_ps,
                    double angle_gain_per_rad, double intensity_gain_mm) {
  Material m;
  m.name = std::move(name);
  m.albedo = albedo;
  m.subsurface_fraction = fraction;
  m.subsurface_delay_ps = delay_ps;
  m.subsurface_angle_gain_per_rad = angle_gain_per_rad;
  m.intensity_bias_gain_mm = intensity_gain_mm;
  return m;
}

Material WithModel(Material m, double c1_mm, double c2, double c3_mm_per_rad) {
  m.model_c1_mm = c1_mm;
  m.model_c2 = c2;
  m.model_c3_mm_per_rad = c3_mm_per_rad;
  return m;
}

}  // namespace

void Material::Check() const {
  Require(albedo >= 0.0 && albedo <= 1.0, "Material.albedo must lie in [0, 1]");
  Require(subsurface_fraction >= 0.0 && subsurface_fraction <= 1.0,
          "Material.subsurface_fraction must lie in [0, 1]");
  Require(subsurface_delay_ps >= 0.0, "Material.subsurface_delay_ps must be >= 0");
  Require(std::isfinite(subsurface_angle_gain_per_rad),
          "Material.subsurface_angle_gain_per_rad must be finite");
  Require(std::isfinite(intensity_bias_gain_mm), "Material.intensity_bias_gain_mm must be finite");
  Require(
      std::isfinite(model_c1_mm) && std::isfinite(model_c2) && std::isfinite(model_c3_mm_per_rad),
      "Material.model_c1_mm/c2/c3 must be finite");
  Require(retro_coefficient >= 0.0, "Material.retro_coefficient must be >= 0");
  Require(retro_observation_falloff_rad > 0.0,
          "Material.retro_observation_falloff_rad must be > 0");
  Require(retro_entrance_cutoff_rad > 0.0 && retro_entrance_cutoff_rad <= 0.5 * std::numbers::pi,
          "Material.retro_entrance_cutoff_rad must lie in (0, pi/2]");
  Require(std::isfinite(retro_curve_amplitude_mm),
          "Material.retro_curve_amplitude_mm must be finite");
}

// Physical presets: bias ~ a c tau / 2 (7.49 mm per 50 ps at a = 1), a grows with theta, and the
// intensity term lowers the bias at close range. Nylon, photopolymer and PLA are calibrated on the
// paper's materials plate and Table I phantoms, skin on its skin study (docs/simulator.md 10).
// Model presets: docs/tof_physics.md section 5.2.
Material SkinMaterial() {
  return WithModel(Subsurface("skin", 0.55, 0.9, 52.0, 0.3, 0.5), 2.8, 0.010, 4.0);
}

Material NylonMaterial() {
  return WithModel(Subsurface("nylon", 0.6, 0.75, 60.0, 0.3, 3.5), 2.7, 0.012, 3.7);
}

Material PhotopolymerMaterial() {
  return WithModel(Subsurface("photopolymer", 0.7, 0.75, 115.0, 0.36, 2.6), 9.2, 0.007, 5.5);
}

Material PlaMaterial() {
  return WithModel(Subsurface("pla", 0.5, 0.4, 300.0, 0.7, 5.0), 17.0, 0.010, 12.0);
}

Material PcAbsMaterial() { return Subsurface("pc_abs", 0.05, 0.5, 50.0, 0.0, 0.0); }

Material RetroReflectiveMaterial(RetroCurve curve) {
  Material m;
  m.name = "retro_reflective";
  m.albedo = 0.3;  // the diffuse base of the sheeting, seen beyond the entrance cut-off
  m.retro_reflective = true;
  m.retro_curve = curve;
  // The sheeting reads farther the more obliquely it is lit: 2.1 mm/rad puts the linear stage's
  // 0-30 deg difference at 0.95 mm against the published 1.08 mm (docs/simulator.md 10).
  m.retro_angle_gain_mm_per_rad = 2.1;
  return m;
}

Material DiffuseMaterial(double albedo) {
  Material m;
  m.name = "diffuse";
  m.albedo = albedo;
  return m;
}

Material DrapeMaterial() {
  Material m = DiffuseMaterial(0.5);
  m.name = "drape";
  return m;
}

double RetroRangeBiasMm(RetroCurve curve, double amplitude_mm, double range_mm) {
  const double scale = amplitude_mm / kCurveSpanMm;
  const double d = std::clamp(range_mm, kCurveStartMm, kCurveEndMm);
  double value = UnitCurveMm(curve, d);
  if (d != range_mm) {  // linear extension with the end slope (central difference)
    constexpr double kStepMm = 1e-3;
    const double inner = d == kCurveStartMm ? d + kStepMm : d - kStepMm;
    const double slope = (UnitCurveMm(curve, d) - UnitCurveMm(curve, inner)) / (d - inner);
    value += slope * (range_mm - d);
  }
  return scale * value;
}

}  // namespace tofnav::sim
