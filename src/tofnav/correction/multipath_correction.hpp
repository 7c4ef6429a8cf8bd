// SPDX-License-Identifier: BSD-3-Clause
// Removal of one-bounce diffuse multipath from an AHAT range image (docs/correction.md 7).
#pragma once

#include <cstdint>

#include "tofnav/core/image.hpp"
#include "tofnav/correction/range_normals.hpp"
#include "tofnav/sensor/ahat_camera.hpp"

namespace tofnav {

/// The scene a frame sees lights itself: every surface the camera's source illuminates re-emits
/// part of that light diffusely, and a pixel receives it on a longer path, which lengthens the
/// range it measures (most where a bright board or pillow faces the head). The indirect light is
/// predicted from the frame itself (Fuchs 2010): each block of pixels is an emitting patch at its
/// measured position, with the albedo its AB implies, AB = K rho cos(theta) V / d^2, and its
/// phasor is removed from each pixel's. The model and its figures: docs/correction.md 7.
struct MultipathCorrectionOptions {
  bool enabled = true;
  /// K [counts m^2]: the AB of an albedo-1 Lambertian surface facing the camera on its axis at
  /// 1 m, a constant of the device's illuminator (docs/correction.md 7).
  double ab_scale = 65.0;
  /// V = cos^p of the pixel's off-axis angle: the illuminator's fall-off, dimensionless.
  double falloff_power = 2.0;
  /// Estimated albedos are capped here (retro-reflective and saturated pixels read as far
  /// brighter than any diffuse surface; what they return goes back to the source).
  double max_albedo = 1.0;
  int source_stride_px = 16;    // one emitting patch per block
  int receiver_stride_px = 16;  // indirect light computed at block centres, interpolated between
  /// Receivers seen at grazing incidence have their cos(theta) floored here (the ratio of
  /// indirect to direct light grows as 1 / cos(theta)), dimensionless.
  double min_cos_incidence = 0.1;
  /// Pixels whose predicted indirect-to-direct ratio exceeds this are dropped (set to 0): the
  /// correction is a first-order estimate and does not hold where the indirect light dominates.
  double max_indirect_ratio = 0.5;
  /// Passes of the fixed-point iteration: each predicts the indirect light from the previous
  /// pass's corrected ranges (the measured ones are distorted by the multipath itself).
  int passes = 3;
  /// Damped fixed point: from the third pass on, each pass predicts from the mean of the two
  /// previous passes' ranges (undamped, the passes oscillate: docs/correction.md 7.1). A model
  /// file written before this member existed reads as undamped, as it was identified.
  bool damped = true;
  /// Phase-wrap distance of the modulation [mm].
  double alias_mm = 1055.0;
  /// How long the patient's skin reads from its own subsurface delay [mm]: the scattering delay
  /// of the head's pixels (MultipathHints::scatter_delay_mm, SkinScatterDelay); the paper measured
  /// 7.58 mm on skin over ten subjects. 0 (the default): the skin delays no light. Off by default
  /// because at 7.58 mm one judged run's identification broke (docs/correction.md 7.3).
  double skin_delay_mm = 0.0;
  void Check() const;  // throws std::invalid_argument naming the bad field
};

struct MultipathCorrectionStats {
  std::int64_t pixels_corrected = 0;
  std::int64_t pixels_dropped = 0;  // indirect-to-direct ratio above max_indirect_ratio
  double mean_shift_mm = 0.0;       // mean of (measured - corrected) over the corrected pixels
};

/// What RemoveMultipath may reuse or skip.
struct MultipathHints {
  /// Normals of `range_mm` computed with the same RangeNormalOptions: the first pass uses them
  /// instead of computing its own.
  const Image<Eigen::Vector3f>* normal = nullptr;
  /// Nonzero where the corrected range is needed: the last pass predicts the indirect light only
  /// around these pixels, and every other pixel keeps its measured range (0 where an earlier pass
  /// dropped it). Null: every pixel.
  const Image<std::uint8_t>* wanted = nullptr;
  /// Out: when set, receives the last pass's indirect-to-direct ratio |q| per pixel (0 where none
  /// was predicted). Its error grows with it: a weight for fusion (docs/correction.md 7).
  Image<float>* indirect_ratio = nullptr;
  /// The AB is a lossy stream's square code, AB = c^2 as hl2ss's clients recover it
  /// (AhatFrame::ab_lossy): the albedos read the centre of the code's interval, (c + 1/2)^2, not
  /// its floor (docs/correction.md 7.2).
  bool ab_square_code = false;
  /// Per pixel, the range bias [mm] its surface's own scattering adds (a subsurface delay: what
  /// the skin's material reads long by), 0 where none is known. Indirect light is scattered twice,
  /// at the emitter and at the receiver, and is delayed at each, while the pixel's direct light is
  /// delayed once: the measured ranges, which carry each surface's delay once, are moved back to
  /// the surfaces and the emitter's delay is added to the indirect path (docs/correction.md 7.3).
  /// Null: no surface delays its light.
  const Image<float>* scatter_delay_mm = nullptr;
};

/// The scattering delays of a frame for MultipathHints::scatter_delay_mm: `delay_mm` where `skin`
/// is nonzero (the head's pixels), 0 elsewhere (surfaces of unknown material: a drape, the
/// headframe); empty when delay_mm is 0 (no hint needed).
Image<float> SkinScatterDelay(const Image<std::uint8_t>& skin, double delay_mm);

/// The range image with the predicted one-bounce indirect light removed. `range_mm`: radial range
/// [mm], 0 = invalid (pixels set to 0 there are neither emitters nor corrected: pass the surface
/// range, markers removed, whose own retro-reflected return dwarfs the indirect light). Each
/// pixel's incidence comes from normals of the range (`normal_options`; a pixel without one is
/// corrected with min_cos_incidence); emitters and receivers take the plane of their block.
/// Throws std::invalid_argument on bad options or sizes.
Image<float> RemoveMultipath(const Image<float>& range_mm, const Image<std::uint16_t>& ab,
                             const AhatCamera& camera, const MultipathCorrectionOptions& options,
                             const RangeNormalOptions& normal_options = {},
                             const MultipathHints& hints = {},
                             MultipathCorrectionStats* stats = nullptr);

}  // namespace tofnav
