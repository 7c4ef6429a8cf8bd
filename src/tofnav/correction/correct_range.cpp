// SPDX-License-Identifier: BSD-3-Clause
// Depth correction of a whole AHAT frame: Eq. (4) on the head surface, Eq. (2) on markers.
#include "tofnav/correction/correct_range.hpp"

#include <cmath>

namespace tofnav {

Image<float> SurfaceRange(const Image<float>& range_mm, const FrameSegmentation& segmentation) {
  Image<float> out = range_mm;
  for (std::size_t i = 0; i < out.size(); ++i) {
    const auto label = static_cast<PixelClass>(segmentation.labels.pixels()[i]);
    if (label == PixelClass::kMarker || label == PixelClass::kTransition) out.pixels()[i] = 0.0f;
  }
  return out;
}

CorrectedFrame CorrectFrame(const AhatFrame& frame, const AhatCamera& camera,
                            const DepthErrorModel& model, const CorrectRangeOptions& options) {
  model.Check();
  CorrectedFrame out;
  out.segmentation = SegmentFrame(frame, camera, options.segmentation);
  Image<float> measured = RangeAsFloat(frame.range_mm);
  const Image<float> surface_measured = SurfaceRange(measured, out.segmentation);
  out.normals = ComputeRangeNormals(surface_measured, camera, options.normals);
  if (model.multipath.enabled) {
    // Surface pixels only change; markers keep their measured range for Eq. (2). Only the pixels
    // Eq. (4) corrects below are needed, and the normals are those of the same surface range.
    // The head's pixels are the patient's skin, whose subsurface delay the indirect light picks up
    // at each scattering (docs/correction.md 7.3).
    const bool delays = model.multipath.skin_delay_mm != 0.0;
    Image<std::uint8_t> wanted(measured.width(), measured.height(), 0),
        skin(delays ? measured.width() : 0, delays ? measured.height() : 0, 0);
    for (std::size_t i = 0; i < wanted.size(); ++i) {
      const auto label = static_cast<PixelClass>(out.segmentation.labels.pixels()[i]);
      if (delays) skin.pixels()[i] = label == PixelClass::kHead;
      wanted.pixels()[i] =
          label == PixelClass::kHead || (label == PixelClass::kOutside && !options.roi_only);
    }
    const Image<float> delay = SkinScatterDelay(skin, model.multipath.skin_delay_mm);
    const Image<float> surface =
        RemoveMultipath(surface_measured, frame.ab, camera, model.multipath, options.normals,
                        {.normal = &out.normals.normal,
                         .wanted = &wanted,
                         .indirect_ratio = &out.indirect_ratio,
                         .ab_square_code = frame.ab_lossy,
                         .scatter_delay_mm = delay.size() > 0 ? &delay : nullptr});
    for (std::size_t i = 0; i < measured.size(); ++i) {
      const auto label = static_cast<PixelClass>(out.segmentation.labels.pixels()[i]);
      if (label != PixelClass::kMarker && label != PixelClass::kTransition) {
        measured.pixels()[i] = surface.pixels()[i];
      }
    }
  }
  options.intensity_ab.Check();
  const Image<float> decoded_ab = model.use_intensity && options.intensity_ab.window_mean
                                      ? DecodedAb(frame.ab, frame.ab_lossy)
                                      : Image<float>();
  const int w = measured.width(), h = measured.height();
  out.range_mm = Image<float>(w, h);
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      const float d = measured(u, v);
      if (d <= 0.0f || !camera.IsValid(u, v)) continue;
      const auto label = static_cast<PixelClass>(out.segmentation.labels(u, v));
      if (label == PixelClass::kTransition) continue;
      if (label == PixelClass::kMarker) {
        out.range_mm(u, v) = static_cast<float>(CorrectMarkerRange(d, options.marker_model));
        continue;
      }
      if (label == PixelClass::kOutside && options.roi_only) continue;
      double theta = out.normals.incidence_rad(u, v);
      if (std::isnan(theta)) {
        if (options.drop_without_normal) continue;
        theta = 0.0;
      }
      if (theta > options.max_incidence_rad) continue;
      const double ab = model.use_intensity ? IntensityAbAt(frame.ab, decoded_ab, surface_measured,
                                                            u, v, options.intensity_ab)
                                            : 0.0;
      const double corrected = model.CorrectRangeMm(d, theta, ab);
      if (corrected > 0.0) out.range_mm(u, v) = static_cast<float>(corrected);
    }
  }
  return out;
}

Image<float> CorrectRangeImage(const AhatFrame& frame, const AhatCamera& camera,
                               const DepthErrorModel& model, const CorrectRangeOptions& options) {
  return CorrectFrame(frame, camera, model, options).range_mm;
}

}  // namespace tofnav
