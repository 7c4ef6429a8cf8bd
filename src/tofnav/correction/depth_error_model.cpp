// SPDX-License-Identifier: BSD-3-Clause
// The surface depth-error model (Eq. 3) with its variants, and its inverse, Eq. (4).
#include "tofnav/correction/depth_error_model.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace tofnav {

double CyclicRangeError::Mm(double phase_range_mm) const {
  if (!enabled()) return 0.0;
  return amplitude_mm * std::sin(2.0 * std::numbers::pi * phase_range_mm / period_mm + phase_rad);
}

double CyclicRangeError::RemoveMm(double measured_range_mm) const {
  if (!enabled()) return measured_range_mm;
  // d = d_m - w(d): the slope of w is at most 2 pi A / P (0.02 for 1 mm at 352 mm), so two
  // fixed-point steps leave under 1e-5 mm.
  double d = measured_range_mm - Mm(measured_range_mm);
  d = measured_range_mm - Mm(d);
  return measured_range_mm - Mm(d);
}

void CyclicRangeError::Check() const {
  if (!std::isfinite(amplitude_mm) || !std::isfinite(period_mm) || !std::isfinite(phase_rad)) {
    throw std::invalid_argument("CyclicRangeError: values must be finite");
  }
  if (amplitude_mm < 0.0) throw std::invalid_argument("CyclicRangeError: amplitude must be >= 0");
  if (enabled() && !(period_mm > 0.0)) {
    throw std::invalid_argument("CyclicRangeError: period must be > 0");
  }
}

namespace {

double AngleTermValue(AngleTerm term, double theta_rad) {
  switch (term) {
    case AngleTerm::kThetaSquared:
      return theta_rad * theta_rad;
    case AngleTerm::kOneMinusCos:
      return 1.0 - std::cos(theta_rad);
    case AngleTerm::kTheta:
      break;
  }
  return theta_rad;
}

}  // namespace

double DepthErrorModel::AngleFeature(double theta_rad) const {
  return AngleTermValue(angle_term, theta_rad) - AngleTermValue(angle_term, theta_reference_rad);
}

DepthErrorModel DepthErrorModel::WithReferences(double theta_ref_rad, double ab_ref) const {
  DepthErrorModel out = *this;
  out.theta_reference_rad = theta_ref_rad;
  out.ab_reference = ab_ref;
  out.c1_mm = c1_mm + c3_mm * AngleFeature(theta_ref_rad) + c4_mm * IntensityFeature(ab_ref);
  out.Check();
  return out;
}

double DepthErrorModel::IntensityFeature(double ab) const {
  if (!use_intensity) return 0.0;
  return std::log(ab_reference / std::max(ab, 1.0));
}

double DepthErrorModel::BiasMm(double true_range_mm, double theta_rad, double ab) const {
  const double bias_mm =
      c1_mm + c2 * true_range_mm + c3_mm * AngleFeature(theta_rad) + c4_mm * IntensityFeature(ab);
  return bias_mm + cyclic.Mm(true_range_mm + bias_mm);
}

double DepthErrorModel::CorrectRangeMm(double measured_range_mm, double theta_rad,
                                       double ab) const {
  return CorrectDecycledRangeMm(cyclic.RemoveMm(measured_range_mm), theta_rad, ab);
}

double DepthErrorModel::CorrectDecycledRangeMm(double decycled_range_mm, double theta_rad,
                                               double ab) const {
  return (decycled_range_mm - c1_mm - c3_mm * AngleFeature(theta_rad) -
          c4_mm * IntensityFeature(ab)) /
         (1.0 + c2);
}

std::string DepthErrorModel::Name() const {
  const std::string angle(AngleTermName(angle_term));
  if (!use_range_term) return (use_intensity ? "intensity-" : "offset-") + angle;
  return "linear-" + angle + (use_intensity ? "+ab" : "");
}

void DepthErrorModel::Check() const {
  if (!std::isfinite(c1_mm) || !std::isfinite(c2) || !std::isfinite(c3_mm) ||
      !std::isfinite(c4_mm)) {
    throw std::invalid_argument("DepthErrorModel: coefficients must be finite");
  }
  if (c2 <= -1.0) throw std::invalid_argument("DepthErrorModel: c2 must be > -1");
  if (!use_range_term && c2 != 0.0) {
    throw std::invalid_argument("DepthErrorModel: c2 must be 0 without the range term");
  }
  if (!(ab_reference > 0.0) || !std::isfinite(ab_reference)) {
    throw std::invalid_argument("DepthErrorModel: ab_reference must be > 0");
  }
  if (!(theta_reference_rad >= 0.0 && theta_reference_rad <= 0.5 * std::numbers::pi)) {
    throw std::invalid_argument("DepthErrorModel: theta_reference_rad must be in [0, pi/2]");
  }
  cyclic.Check();
}

DepthErrorModel IntensityFormModel() {
  DepthErrorModel model;
  model.use_intensity = true;
  model.use_range_term = false;
  return model;
}

std::vector<double> FreeParameterValues(const DepthErrorModel& model,
                                        const std::array<double, 4>& per_coefficient) {
  std::vector<double> out = {per_coefficient[0]};
  if (model.use_range_term) out.push_back(per_coefficient[1]);
  out.push_back(per_coefficient[2]);
  if (model.use_intensity) out.push_back(per_coefficient[3]);
  return out;
}

std::vector<double> ModelParameters(const DepthErrorModel& model) {
  return FreeParameterValues(model, {model.c1_mm, model.c2, model.c3_mm, model.c4_mm});
}

void SetModelParameters(DepthErrorModel& model, const std::vector<double>& parameters) {
  const std::size_t expected = FreeParameterValues(model, {}).size();
  if (parameters.size() != expected) {
    throw std::invalid_argument("SetModelParameters: wrong parameter count");
  }
  std::size_t i = 0;
  model.c1_mm = parameters[i++];
  model.c2 = model.use_range_term ? parameters[i++] : 0.0;
  model.c3_mm = parameters[i++];
  model.c4_mm = model.use_intensity ? parameters[i] : 0.0;
}

std::string_view AngleTermName(AngleTerm term) {
  switch (term) {
    case AngleTerm::kThetaSquared:
      return "theta2";
    case AngleTerm::kOneMinusCos:
      return "1-cos";
    case AngleTerm::kTheta:
      break;
  }
  return "theta";
}

AngleTerm ParseAngleTerm(std::string_view name) {
  for (AngleTerm t : {AngleTerm::kTheta, AngleTerm::kThetaSquared, AngleTerm::kOneMinusCos}) {
    if (AngleTermName(t) == name) return t;
  }
  throw std::invalid_argument("unknown angle term '" + std::string(name) +
                              "' (theta, theta2, 1-cos)");
}

}  // namespace tofnav
