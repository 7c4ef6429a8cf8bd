// SPDX-License-Identifier: BSD-3-Clause
// Shared pieces of the tracking end-to-end runs: the simulator's true f_rf and error statistics.
#pragma once

#include <cmath>
#include <cstdio>
#include <vector>

#include "marker_test_scenes.hpp"
#include "tofnav/correction/marker_range_model.hpp"
#include "tofnav/sim/material.hpp"
#include "tofnav/sim/tof_model.hpp"

namespace tofnav::testing {

/// The simulator's whole range error of retro hits as a function of the *measured* range:
/// f_rf(d) at the true range plus the wiggle at the observed range (tof_model), interpolated
/// (p = 1) on 1 mm steps of the true range over 150-1000 mm, with the sheeting's own
/// entrance-angle gain (docs/tracking.md 4).
inline MarkerRangeModel TrueRangeModel(const sim::Material& retro,
                                       const sim::SensorOptions& sensor) {
  std::vector<MarkerRangeSample> samples;
  for (double d = 150.0; d <= 1000.0; d += 1.0) {
    const double observed =
        d + sim::RetroRangeBiasMm(retro.retro_curve, retro.retro_curve_amplitude_mm, d);
    const double total = observed + sim::WiggleMm(sensor, observed) - d;
    samples.push_back({d + total, total, 1.0});
  }
  MarkerRangeModel model = FitMarkerRangeModel(samples, {.smoothing_p = 1.0}).model;
  model.entrance_gain_mm_per_rad = retro.retro_angle_gain_mm_per_rad;
  return model;
}

/// Root mean square of the values.
inline double Rms(const std::vector<double>& v) {
  double s = 0.0;
  for (const double x : v) s += x * x;
  return v.empty() ? 0.0 : std::sqrt(s / static_cast<double>(v.size()));
}

inline double Mean(const std::vector<double>& v) {
  double s = 0.0;
  for (const double x : v) s += x;
  return v.empty() ? 0.0 : s / static_cast<double>(v.size());
}

}  // namespace tofnav::testing
