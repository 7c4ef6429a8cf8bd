// SPDX-License-Identifier: BSD-3-Clause
// Marker, transitional and head-surface areas of one AHAT frame (Sec. III-A.4).
#include "tofnav/correction/frame_segmentation.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "tofnav/markers/bright_blobs.hpp"

namespace tofnav {
namespace {

bool ValidRange(std::uint16_t code, const SegmentationOptions& options) {
  return code > 0 && code < kAhatInvalidRange && code >= options.min_range_mm &&
         code <= options.max_range_mm;
}

std::uint16_t ThresholdCounts(double threshold) {
  return static_cast<std::uint16_t>(std::clamp(std::ceil(threshold), 1.0, 65535.0));
}

// Marks the transitional band: every pixel within `radius` (Chebyshev) of a marker pixel that is
// not itself a marker pixel. Separable: a row pass then a column pass over a marker mask.
void MarkTransition(Image<std::uint8_t>& labels, int radius) {
  const int w = labels.width(), h = labels.height();
  Image<std::uint8_t> rows(w, h);
  for (int v = 0; v < h; ++v) {
    int last = -1'000'000;
    for (int u = 0; u < w; ++u) {
      if (labels(u, v) == static_cast<std::uint8_t>(PixelClass::kMarker)) last = u;
      if (u - last <= radius) rows(u, v) = 1;
    }
    last = 1'000'000;
    for (int u = w - 1; u >= 0; --u) {
      if (labels(u, v) == static_cast<std::uint8_t>(PixelClass::kMarker)) last = u;
      if (last - u <= radius) rows(u, v) = 1;
    }
  }
  for (int u = 0; u < w; ++u) {
    for (int v = 0; v < h; ++v) {
      bool near = false;
      for (int dv = std::max(-radius, -v); dv <= std::min(radius, h - 1 - v) && !near; ++dv) {
        near = rows(u, v + dv) != 0;
      }
      std::uint8_t& label = labels(u, v);
      if (near && label != static_cast<std::uint8_t>(PixelClass::kMarker)) {
        label = static_cast<std::uint8_t>(PixelClass::kTransition);
      }
    }
  }
}

}  // namespace

void SegmentationOptions::Check() const {
  if (!(marker_ab_threshold >= 1.0)) {
    throw std::invalid_argument("SegmentationOptions::marker_ab_threshold must be >= 1");
  }
  if (min_marker_area_px < 1 || max_marker_area_px < min_marker_area_px) {
    throw std::invalid_argument("SegmentationOptions: need 1 <= min_marker_area_px <= max");
  }
  if (transition_dilation_px < 0 || transition_dilation_px > 50) {
    throw std::invalid_argument("SegmentationOptions::transition_dilation_px must be in [0, 50]");
  }
  head_region.Check();
  if (!(min_range_mm >= 0.0) || !(max_range_mm > min_range_mm) || !(roi_radius_mm >= 0.0)) {
    throw std::invalid_argument("SegmentationOptions: bad range window or roi_radius_mm");
  }
}

FrameSegmentation SegmentFrame(const AhatFrame& frame, const AhatCamera& camera,
                               const SegmentationOptions& options) {
  options.Check();
  const int w = camera.width(), h = camera.height();
  if (frame.range_mm.width() != w || frame.range_mm.height() != h || frame.ab.width() != w ||
      frame.ab.height() != h) {
    throw std::invalid_argument("SegmentFrame: frame and camera sizes differ");
  }
  FrameSegmentation out{Image<std::uint8_t>(w, h), {}, 0};
  const BrightBlobs blobs = FindBrightBlobs(frame.ab, ThresholdCounts(options.marker_ab_threshold));
  for (const BrightBlob& blob : blobs.blobs) {
    if (blob.area_px < options.min_marker_area_px || blob.area_px > options.max_marker_area_px) {
      continue;
    }
    MarkerArea area;
    for (int r = blob.first_run; r < blob.first_run + blob.run_count; ++r) {
      const PixelRun& run = blobs.runs[static_cast<std::size_t>(r)];
      for (int u = run.u_begin; u < run.u_end; ++u) {
        out.labels(u, run.v) = static_cast<std::uint8_t>(PixelClass::kMarker);
        const std::uint16_t code = frame.range_mm(u, run.v);
        if (!ValidRange(code, options) || !camera.IsValid(u, run.v)) continue;
        area.pixels.emplace_back(u, run.v);
        area.centroid_in_ahat += camera.PixelRay(u, run.v).cast<double>() * code;
      }
    }
    if (area.pixels.empty()) continue;
    area.centroid_in_ahat /= static_cast<double>(area.pixels.size());
    out.markers.push_back(std::move(area));
  }
  MarkTransition(out.labels, options.transition_dilation_px);

  Image<float> surface(w, h, 0.0f);
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      const std::uint16_t code = frame.range_mm(u, v);
      if (out.labels(u, v) != static_cast<std::uint8_t>(PixelClass::kOutside) ||
          !ValidRange(code, options) || !camera.IsValid(u, v)) {
        continue;
      }
      surface(u, v) = static_cast<float>(code);
    }
  }
  out.region = SelectHeadRegion(surface, camera, options.head_region);
  Eigen::Vector3d roi_centre = Eigen::Vector3d::Zero();
  bool use_roi = false;
  if (options.roi_radius_mm > 0.0 && options.head_region.enabled && out.region.pixels > 0) {
    for (int v = 0; v < h; ++v) {
      for (int u = 0; u < w; ++u) {
        if (out.region.mask(u, v) != 0)
          roi_centre += camera.PixelRay(u, v).cast<double>() * surface(u, v);
      }
    }
    roi_centre /= static_cast<double>(out.region.pixels);
    use_roi = true;
  } else if (options.roi_radius_mm > 0.0 && !out.markers.empty()) {
    for (const MarkerArea& m : out.markers) roi_centre += m.centroid_in_ahat;
    roi_centre /= static_cast<double>(out.markers.size());
    use_roi = true;
  }
  const double roi_sq = options.roi_radius_mm * options.roi_radius_mm;
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      if (out.region.mask(u, v) == 0) continue;
      if (use_roi &&
          (camera.PixelRay(u, v).cast<double>() * surface(u, v) - roi_centre).squaredNorm() >
              roi_sq) {
        continue;
      }
      out.labels(u, v) = static_cast<std::uint8_t>(PixelClass::kHead);
      ++out.head_pixels;
    }
  }
  return out;
}

}  // namespace tofnav
