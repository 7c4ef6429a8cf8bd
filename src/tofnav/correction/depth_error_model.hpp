// SPDX-License-Identifier: BSD-3-Clause
// The surface depth-error model (Eq. 3) with its variants, and its inverse, Eq. (4).
#pragma once

#include <array>
#include <string>
#include <string_view>
#include <vector>

#include "tofnav/correction/multipath_correction.hpp"

namespace tofnav {

/// How the incidence angle enters the model (beyond the paper: docs/tof_physics.md section 11).
enum class AngleTerm {
  kTheta,         // C3 * theta: the paper's Eq. (3)
  kThetaSquared,  // C3 * theta^2
  kOneMinusCos,   // C3 * (1 - cos theta)
};

/// Per-frame residual of an identification (Eq. 7 terms at the solution).
struct FrameResidual {
  int frame = 0;           // index in the recording
  double err_c_mm = -1.0;  // Eq. (5), -1 when not evaluated (no CT or ICP failed)
  double err_s_mm = -1.0;  // RMS over the frame's markers of Eq. (6), -1 when none
  int markers = 0;         // markers contributing to Err_S
};

/// One physical marker (a sticker) across the identification's frames.
struct StickerUse {
  std::array<double, 3> centre_mm{};  // in `world` (in `ahat` when the frames have no rig pose)
  int observations = 0;               // frames in which its patch entered the fit
  int rejected = 0;                   // of those, left out as not on the skin (second fit)
};

/// What the identification did and how well it fits (written to depth_model.json).
struct DepthModelFitReport {
  std::string method;            // e.g. "levenberg-marquardt"
  std::string costs;             // "correctness+smoothness" or "smoothness"
  int frames_used = 0;           // frames with a head or a marker patch after the screening
  int frames_left_out = 0;       // screened out whole: foreground (a hand) in front of the head
  int head_points_left_out = 0;  // foreground points removed from the frames kept
  int marker_patches_screened_out = 0;   // patches whose surroundings were foreground
  int marker_observations_curved = 0;    // markers on the head too curved for a sticker (a sphere)
  int marker_observations = 0;           // marker patches (a marker in a frame) in the first fit
  int marker_observations_rejected = 0;  // of those, left out as not on the skin (second fit)
  std::vector<StickerUse> markers;       // per physical marker
  int evaluations = 0;
  double initial_cost = 0.0;  // Eq. (7) at the start [mm^2]
  double final_cost = 0.0;    // Eq. (7) at the solution [mm^2]
  double seconds = 0.0;
  /// Standard errors from the Gauss-Newton covariance, of the free parameters in order
  /// (C1[, C2], C3[, C4]: ModelParameters).
  std::vector<double> standard_errors;
  /// Cross-validation of the variants: name -> held-out cost [mm^2] (empty when not run).
  std::vector<std::pair<std::string, double>> cross_validation;
  std::vector<FrameResidual> frames;
};

/// The sensor's cyclic (wiggling) range error, w(d) = A sin(2 pi d / P + phi) at the phase range d
/// [mm]: harmonics of the modulation alias into a period of L / N (docs/tof_physics.md 5.4). It
/// belongs to the sensor, not the material: given (held fixed) or fitted with the coefficients at
/// a given period (IdentificationOptions::fit_cyclic_period_mm, docs/correction.md 2.2). Off
/// when A = 0.
struct CyclicRangeError {
  double amplitude_mm = 0.0;
  double period_mm = 0.0;
  double phase_rad = 0.0;
  bool enabled() const { return amplitude_mm != 0.0; }
  bool operator==(const CyclicRangeError&) const = default;
  /// w(d) at the range the sensor measured before the cyclic error was added.
  double Mm(double phase_range_mm) const;
  /// The phase range d from a measured range d_m = d + w(d) (fixed point; |w'| << 1).
  double RemoveMm(double measured_range_mm) const;
  /// Throws std::invalid_argument on a non-finite value, A < 0 or, when A > 0, P <= 0.
  void Check() const;
};

/// delta_d = C1 + C2 d + C3 (g(theta) - g(theta_ref)) + C4 ln(AB_ref / AB): measured minus true
/// range [mm] of a surface pixel at true range d [mm], incidence theta [rad] and active brightness
/// AB [counts] (Eq. 3 with the angle term g = theta, theta_ref = 0 and C4 = 0). The intensity term
/// (C4, off unless use_intensity) is 0 at AB = ab_reference, the angle term at theta_reference_rad:
/// C1 is the bias at the reference conditions. The identification puts them at its head samples'
/// medians, where C1 is well determined (docs/correction.md 2.7). Without the range term
/// (use_range_term false) C2 is held at 0: with the intensity term on, the range enters through AB
/// ~ cos(theta) / d^2, and C2 d and C4 ln(1 / AB) are nearly collinear over 300-700 mm
/// (docs/correction.md 2.1).
struct DepthErrorModel {
  AngleTerm angle_term = AngleTerm::kTheta;
  bool use_intensity = false;
  bool use_range_term = true;
  double c1_mm = 0.0;
  double c2 = 0.0;                   // dimensionless (mm per mm)
  double c3_mm = 0.0;                // mm per unit of g(theta) (mm/rad for kTheta)
  double c4_mm = 0.0;                // mm per unit of ln(AB_ref / AB)
  double ab_reference = 130.0;       // counts
  double theta_reference_rad = 0.0;  // in [0, pi/2]
  /// Multipath removed from the measured range before Eq. (4) (and before the identification that
  /// fitted C1..C4): the model holds only for ranges prepared the same way. Off for a model that
  /// does not say (files written before it existed).
  MultipathCorrectionOptions multipath = {.enabled = false};
  /// Removed from the measured range first, before the terms above (not fitted by the
  /// identification: it is the sensor's). Off for files written before it existed.
  CyclicRangeError cyclic;
  DepthModelFitReport report;

  /// g(theta) - g(theta_reference_rad) of the chosen angle term.
  double AngleFeature(double theta_rad) const;
  /// ln(ab_reference / AB) when use_intensity (AB clamped to >= 1), else 0.
  double IntensityFeature(double ab) const;
  /// delta_d at true range d (Eq. 3), plus the cyclic error at the range it produced.
  double BiasMm(double true_range_mm, double theta_rad, double ab = 0.0) const;
  /// Eq. (4): true range from a measured one, d = (d'_m - C1 - C3 g - C4 h) / (1 + C2), where d'_m
  /// is d_m with the cyclic error removed.
  double CorrectRangeMm(double measured_range_mm, double theta_rad, double ab = 0.0) const;
  /// The same from d'_m = cyclic.RemoveMm(d_m) computed beforehand (the identification keeps it
  /// while only the coefficients change): exactly CorrectRangeMm's figure.
  double CorrectDecycledRangeMm(double decycled_range_mm, double theta_rad, double ab = 0.0) const;
  /// Model name for reports: "linear-theta", "linear-theta2", "linear-1-cos", plus "+ab"; without
  /// the range term "intensity-theta" (and so on) with the AB term, "offset-theta" without.
  std::string Name() const;
  /// The same bias re-expressed at other reference conditions: C1 becomes the bias (without the
  /// cyclic error) at theta_ref, AB_ref and d = 0; C2, C3 and C4 stay. Exact for every form.
  DepthErrorModel WithReferences(double theta_reference_rad, double ab_reference) const;
  /// Throws std::invalid_argument on non-finite coefficients, C2 <= -1, C2 != 0 without the range
  /// term, AB_ref <= 0 or theta_ref outside [0, pi/2].
  void Check() const;
};

/// The form tofnav identifies by default: C1 + C3 theta + C4 ln(AB_ref / AB), C2 held at 0
/// (docs/correction.md 2.1 gives the measurements that chose it over the paper's Eq. 3).
DepthErrorModel IntensityFormModel();

/// The free parameters as a vector, (C1[, C2], C3[, C4]) as use_range_term and use_intensity
/// say, and back (a coefficient that is not free is set to 0).
std::vector<double> ModelParameters(const DepthErrorModel& model);
void SetModelParameters(DepthErrorModel& model, const std::vector<double>& parameters);
/// Of four per-coefficient values (C1, C2, C3, C4: steps, bounds), those of the free parameters.
std::vector<double> FreeParameterValues(const DepthErrorModel& model,
                                        const std::array<double, 4>& per_coefficient);

std::string_view AngleTermName(AngleTerm term);  // "theta", "theta2", "1-cos"
/// Inverse of AngleTermName; throws std::invalid_argument on an unknown name.
AngleTerm ParseAngleTerm(std::string_view name);

}  // namespace tofnav
