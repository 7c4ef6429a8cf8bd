// SPDX-License-Identifier: BSD-3-Clause
// The sensor's cyclic range error measured on the stage: a diffuse plate beside f_rf-corrected
// tape, over more than one period of range (docs/correction.md 2.8).
#pragma once

#include <cstddef>
#include <span>
#include <vector>

#include "tofnav/correction/depth_error_model.hpp"

namespace tofnav {

/// One pixel of the stage's plate: what it measured and where the reference plane (the
/// f_rf-corrected tape beside it) says the plate is along its ray.
struct PlateRangeSample {
  double measured_range_mm = 0.0;  // d_m
  double plane_range_mm = 0.0;     // the ray's range to the reference plane
  double incidence_rad = 0.0;      // of the ray on the plane
  double ab = 0.0;                 // active brightness [counts], > 0
  int run = 0;                     // stage run, >= 0: each run has its own offset
};

struct PlateCyclicFitOptions {
  int iterations = 12;     // iteratively reweighted least-squares passes
  double huber_k = 1.345;  // Huber threshold in robust (MAD) scales
  std::size_t min_samples = 200;
  /// The samples' plane ranges must span at least this share of the period: over less, a
  /// sinusoid and the plate's smooth range dependence (its AB term) cannot be told apart.
  double min_span_periods = 0.75;
  void Check() const;  // throws std::invalid_argument naming the bad field
};

struct PlateCyclicFit {
  CyclicRangeError cyclic;  // at the period given
  double amplitude_sd_mm = 0.0;
  double phase_sd_rad = 0.0;
  /// The plate material's own bias terms, fitted beside it: per run a constant, and shared
  /// ln(AB_ref / AB) [mm] and incidence [mm/rad] slopes (the intensity form, section 2.1).
  std::vector<double> run_offsets_mm;
  double intensity_mm = 0.0;
  double incidence_mm_per_rad = 0.0;
  double robust_sd_mm = 0.0;  // 1.4826 MAD of the final residuals
  std::size_t samples = 0;
  double span_mm = 0.0;  // max - min plane range of the samples
};

/// d_m - d_plane = b_run + c_AB ln(130 / AB) + c_theta theta + A sin(2 pi d / P + phi), d the
/// phase range d_m - w(d): linear in (b, c, A cos phi, A sin phi) at a fixed period, solved by
/// Huber-weighted least squares. The plate's bias is the material's (its subsurface and
/// brightness terms, constant over a run but for AB); what repeats with period P across the runs
/// is the sensor's. Throws std::invalid_argument on too few samples, a span under
/// min_span_periods, a bad period or option, or a non-finite sample.
PlateCyclicFit FitPlateCyclicError(std::span<const PlateRangeSample> samples, double period_mm,
                                   const PlateCyclicFitOptions& options = {});

}  // namespace tofnav
