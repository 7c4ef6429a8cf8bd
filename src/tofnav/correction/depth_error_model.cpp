// SPDX-License-Identifier: BSD-3-Clause
// The surface depth-error model (Eq. 3) with its variants, and its inverse, Eq. (4).
#include "tofnav/correction/depth_error_model.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace tofnav {

double DepthErrorModel::AngleFeature(double theta_rad) const {
  switch (angle_term) {
    case AngleTerm::kThetaSquared:
      return theta_rad * theta_rad;
    case AngleTerm::kOneMinusCos:
      return 1.0 - std::cos(theta_rad);
    case AngleTerm::kTheta:
      break;
  }
  return theta_rad;
}

double DepthErrorModel::IntensityFeature(double ab) const {
  if (!use_intensity) return 0.0;
  return std::log(ab_reference / std::max(ab, 1.0));
}

double DepthErrorModel::BiasMm(double true_range_mm, double theta_rad, double ab) const {
  return c1_mm + c2 * true_range_mm + c3_mm * AngleFeature(theta_rad) +
         c4_mm * IntensityFeature(ab);
}

double DepthErrorModel::CorrectRangeMm(double measured_range_mm, double theta_rad,
                                       double ab) const {
  return (measured_range_mm - c1_mm - c3_mm * AngleFeature(theta_rad) -
          c4_mm * IntensityFeature(ab)) /
         (1.0 + c2);
}

std::string DepthErrorModel::Name() const {
  std::string name = "linear-" + std::string(AngleTermName(angle_term));
  if (use_intensity) name += "+ab";
  return name;
}

void DepthErrorModel::Check() const {
  if (!std::isfinite(c1_mm) || !std::isfinite(c2) || !std::isfinite(c3_mm) ||
      !std::isfinite(c4_mm)) {
    throw std::invalid_argument("DepthErrorModel: coefficients must be finite");
  }
  if (c2 <= -1.0) throw std::invalid_argument("DepthErrorModel: c2 must be > -1");
  if (!(ab_reference > 0.0) || !std::isfinite(ab_reference)) {
    throw std::invalid_argument("DepthErrorModel: ab_reference must be > 0");
  }
}

std::vector<double> ModelParameters(const DepthErrorModel& model) {
  std::vector<double> p = {model.c1_mm, model.c2, model.c3_mm};
  if (model.use_intensity) p.push_back(model.c4_mm);
  return p;
}

void SetModelParameters(DepthErrorModel& model, const std::vector<double>& parameters) {
  const std::size_t expected = model.use_intensity ? 4 : 3;
  if (parameters.size() != expected) {
    throw std::invalid_argument("SetModelParameters: wrong parameter count");
  }
  model.c1_mm = parameters[0];
  model.c2 = parameters[1];
  model.c3_mm = parameters[2];
  model.c4_mm = model.use_intensity ? parameters[3] : 0.0;
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
