// SPDX-License-Identifier: BSD-3-Clause
// LocateMarkers: threshold, components, gates, centroid, ray and robust range
// (docs/tracking.md 9.1-9.2).
#include "tofnav/markers/marker_detection.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <optional>
#include <utility>

#include "tofnav/core/require.hpp"
#include "tofnav/markers/bright_blobs.hpp"
#include "tofnav/markers/marker_centre.hpp"
#include "tofnav/markers/marker_damage.hpp"

namespace tofnav {
namespace {

constexpr double kMaxAbCounts = 65535.0;
// Blob pixels at or above this fraction of the peak AB count as fully covered by the marker in
// the reference centroid (DetectedMarker::reference_ray_in_ahat).
constexpr double kFullCoverageOfPeak = 0.5;

bool ValidRange(std::uint16_t range_mm) { return range_mm > 0 && range_mm < kAhatInvalidRange; }

double AngleRad(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

std::uint16_t ToCounts(double ab) {
  return static_cast<std::uint16_t>(std::clamp(std::ceil(ab), 1.0, kMaxAbCounts));
}

// Adaptive threshold: the frame's AB percentile from a histogram of 64-count bins (the upper
// edge of the bin that holds it), times the factor.
double AdaptiveThreshold(const Image<std::uint16_t>& ab, const MarkerDetectionOptions& options) {
  if (options.relative_threshold <= 0.0 || ab.empty()) return options.ab_threshold;
  constexpr int kShift = 6;
  std::array<int, (65536 >> kShift)> histogram{};
  for (const std::uint16_t value : ab.pixels()) ++histogram[value >> kShift];
  const double above = (1.0 - options.relative_percentile) * static_cast<double>(ab.size());
  double count = 0.0;
  int bin = static_cast<int>(histogram.size()) - 1;
  for (; bin > 0; --bin) {
    count += histogram[static_cast<std::size_t>(bin)];
    if (count >= above) break;
  }
  const double percentile = static_cast<double>((bin + 1) << kShift);
  return std::max(options.ab_threshold, options.relative_threshold * percentile);
}

// Pixels per radian along u and v at pixel (u, v), from the neighbouring rays.
std::optional<Eigen::Vector2d> LocalFocalPx(const AhatCamera& camera, int u, int v) {
  const auto ray = [&](int x, int y) -> std::optional<Eigen::Vector3d> {
    if (!camera.IsValid(x, y)) return std::nullopt;
    return camera.PixelRay(x, y).cast<double>();
  };
  const std::optional<Eigen::Vector3d> c = ray(u, v);
  if (!c) return std::nullopt;
  Eigen::Vector2d focal;
  for (int axis = 0; axis < 2; ++axis) {
    std::optional<Eigen::Vector3d> n = axis == 0 ? ray(u + 1, v) : ray(u, v + 1);
    if (!n) n = axis == 0 ? ray(u - 1, v) : ray(u, v - 1);
    if (!n) return std::nullopt;
    const double angle = AngleRad(*c, *n);
    if (!(angle > 0.0)) return std::nullopt;
    focal[axis] = 1.0 / angle;
  }
  return focal;
}

class BlobMeasurer {
 public:
  BlobMeasurer(const AhatFrame& frame, const AhatCamera& camera,
               const MarkerDetectionOptions& options, double threshold)
      : frame_(frame), camera_(camera), options_(options), threshold_(threshold) {}

  // The marker of one blob, or nullopt with the reason counted (and border and merged blobs
  // listed in result.dropped).
  std::optional<DetectedMarker> Measure(const BrightBlobs& blobs, const BrightBlob& blob,
                                        MarkerDetectionResult& result) {
    MarkerRejections& rejected = result.rejected;
    const std::span<const PixelRun> runs(blobs.runs.data() + blob.first_run,
                                         static_cast<std::size_t>(blob.run_count));
    const double seed = options_.ab_seed_threshold > 0.0 ? options_.ab_seed_threshold : threshold_;
    if (blob.area_px < options_.min_area_px || blob.area_px > options_.max_area_px) {
      ++rejected.area;
      return std::nullopt;
    }
    if (blob.ab_peak < seed) {
      ++rejected.faint;
      return std::nullopt;
    }
    if (blob.u_min == 0 || blob.v_min == 0 || blob.u_max == frame_.ab.width() - 1 ||
        blob.v_max == frame_.ab.height() - 1 || TouchesFieldEdge(frame_, camera_, runs)) {
      ++rejected.border;
      result.dropped.push_back(Dropped(BlobDropReason::kImageBorder, runs, blob.area_px));
      return std::nullopt;
    }
    DetectedMarker marker;
    marker.area_px = blob.area_px;
    marker.ab_peak = blob.ab_peak;
    const auto [pixel, reference_pixel] =
        WeightedCentroids(runs, kFullCoverageOfPeak * blob.ab_peak);
    marker.pixel = pixel;
    const std::optional<Eigen::Vector3d> ray = camera_.Ray(marker.pixel);
    const std::optional<Eigen::Vector3d> reference_ray = camera_.Ray(reference_pixel);
    if (!ray || !reference_ray) {
      ++rejected.invalid_ray;
      return std::nullopt;
    }
    marker.ray_in_ahat = ray->normalized();
    marker.reference_ray_in_ahat = reference_ray->normalized();
    const double core_level = std::max(threshold_, options_.core_ab_fraction * blob.ab_peak);
    GatherCore(runs, core_level, marker);
    if (static_cast<int>(marker.core.size()) < options_.min_range_px) GatherCore(runs, 0.0, marker);
    if (static_cast<int>(marker.core.size()) < options_.min_range_px) {
      ++rejected.no_depth;
      return std::nullopt;
    }
    ranges_.clear();
    for (const CoreSample& sample : marker.core) ranges_.push_back(sample.range_mm);
    marker.surface_range_mm = TrimmedMean(ranges_);
    const std::optional<Eigen::Vector2d> focal =
        LocalFocalPx(camera_, static_cast<int>(std::lround(marker.pixel.x())),
                     static_cast<int>(std::lround(marker.pixel.y())));
    if (!focal) {
      ++rejected.invalid_ray;
      return std::nullopt;
    }
    marker.pixel_pitch_rad = 1.0 / std::sqrt(focal->prod());
    if (!SizeMatchesRange(marker)) {
      ++rejected.size_range;
      return std::nullopt;
    }
    const double pitch_mm = marker.pixel_pitch_rad * marker.surface_range_mm;
    if (MeasureBlobShape(runs).length_px >
        options_.max_marker_diameter_mm / pitch_mm + options_.merged_margin_px) {
      ++rejected.merged;
      result.dropped.push_back(Dropped(BlobDropReason::kMerged, runs, blob.area_px));
      return std::nullopt;
    }
    marker.damage =
        AssessRing(frame_, blob, runs, threshold_, marker.surface_range_mm, pitch_mm, options_);
    return marker;
  }

 private:
  // AB-weighted centroid, w = AB - threshold + 1 (> 0 on every blob pixel): rim pixels weigh by
  // their coverage, so edges are sub-pixel; the clipped PSF tail is symmetric. The illumination
  // fall-off across a blob (cos^p of the off-axis angle, 1 / d^2) pulls it towards the image
  // centre by ~2e-4 of the off-axis distance (docs/tracking.md 9.2 accepts this for tracking; the
  // stage reference, which must not be biased, uses the capped centroid instead).
  // Returns it and, in the same pass, the reference centroid: weights capped at that of AB =
  // `full_ab` (DetectedMarker::reference_ray_in_ahat).
  std::pair<Eigen::Vector2d, Eigen::Vector2d> WeightedCentroids(std::span<const PixelRun> runs,
                                                                double full_ab) const {
    const double cap = std::max(full_ab - threshold_ + 1.0, 1.0);
    double sum_w = 0.0, sum_u = 0.0, sum_v = 0.0;     // AB-weighted
    double sum_cw = 0.0, sum_cu = 0.0, sum_cv = 0.0;  // capped
    for (const PixelRun& r : runs) {
      const std::uint16_t* row = &frame_.ab(0, r.v);
      double row_w = 0.0, row_cw = 0.0;
      for (int u = r.u_begin; u < r.u_end; ++u) {
        const double w = row[u] - threshold_ + 1.0;
        const double cw = std::min(w, cap);
        row_w += w;
        sum_u += w * u;
        row_cw += cw;
        sum_cu += cw * u;
      }
      sum_w += row_w;
      sum_v += row_w * r.v;
      sum_cw += row_cw;
      sum_cv += row_cw * r.v;
    }
    return {{sum_u / sum_w, sum_v / sum_w}, {sum_cu / sum_cw, sum_cv / sum_cw}};
  }

  // Valid ranges and ray angles of the blob pixels with AB >= level.
  void GatherCore(std::span<const PixelRun> runs, double level, DetectedMarker& marker) const {
    marker.core.clear();
    for (const PixelRun& r : runs) {
      for (int u = r.u_begin; u < r.u_end; ++u) {
        const std::uint16_t range = frame_.range_mm(u, r.v);
        if (frame_.ab(u, r.v) < level || !ValidRange(range) || !camera_.IsValid(u, r.v)) continue;
        const Eigen::Vector3f ray = camera_.PixelRay(u, r.v);
        const double angle = AngleRad(ray.cast<double>(), marker.ray_in_ahat);
        marker.core.push_back({static_cast<float>(range), static_cast<float>(angle), ray});
      }
    }
  }

  // A dropped blob's mean pixel, ray and angular radius (of a disc of its area).
  DroppedBlob Dropped(BlobDropReason reason, std::span<const PixelRun> runs, int area_px) const {
    DroppedBlob d;
    d.reason = reason;
    d.pixel = MeasureBlobShape(runs).mean;
    const std::optional<Eigen::Vector3d> ray = camera_.Ray(d.pixel);
    const std::optional<Eigen::Vector2d> focal =
        LocalFocalPx(camera_, static_cast<int>(std::lround(d.pixel.x())),
                     static_cast<int>(std::lround(d.pixel.y())));
    if (ray && focal) {
      d.ray_in_ahat = ray->normalized();
      d.radius_rad = std::sqrt(area_px / std::numbers::pi / focal->prod());
    }
    return d;
  }

  // Area against pi/4 (D/R)^2 f_u f_v for the min and max diameters: the wrap check of
  // docs/tracking.md 9.2.
  bool SizeMatchesRange(const DetectedMarker& marker) const {
    const double pitch_mm = marker.pixel_pitch_rad * marker.surface_range_mm;
    const double px_per_mm2 = std::numbers::pi / 4.0 / (pitch_mm * pitch_mm);
    const double d_min = options_.min_marker_diameter_mm, d_max = options_.max_marker_diameter_mm;
    return marker.area_px >= options_.min_area_ratio * px_per_mm2 * d_min * d_min &&
           marker.area_px <= options_.max_area_ratio * px_per_mm2 * d_max * d_max;
  }

  const AhatFrame& frame_;
  const AhatCamera& camera_;
  const MarkerDetectionOptions& options_;
  double threshold_;
  std::vector<double> ranges_;
};

}  // namespace

void MarkerDetectionOptions::Check() const {
  Require(ab_threshold >= 1.0 && ab_threshold <= kMaxAbCounts,
          "MarkerDetectionOptions::ab_threshold must be in [1, 65535]");
  Require(ab_seed_threshold >= 0.0 && ab_seed_threshold <= kMaxAbCounts,
          "MarkerDetectionOptions::ab_seed_threshold must be in [0, 65535]");
  Require(relative_threshold >= 0.0 && relative_threshold <= 100.0,
          "MarkerDetectionOptions::relative_threshold must be in [0, 100]");
  Require(relative_percentile > 0.0 && relative_percentile < 1.0,
          "MarkerDetectionOptions::relative_percentile must be in (0, 1)");
  Require(min_area_px >= 1 && max_area_px >= min_area_px,
          "MarkerDetectionOptions::min_area_px must be >= 1 and <= max_area_px");
  Require(min_marker_diameter_mm > 0.0 && max_marker_diameter_mm >= min_marker_diameter_mm,
          "MarkerDetectionOptions::min_marker_diameter_mm must be > 0 and <= the max");
  Require(min_area_ratio >= 0.0 && max_area_ratio > 0.0,
          "MarkerDetectionOptions::min_area_ratio/max_area_ratio must be >= 0 / > 0");
  Require(core_ab_fraction >= 0.0 && core_ab_fraction <= 1.0,
          "MarkerDetectionOptions::core_ab_fraction must be in [0, 1]");
  Require(min_range_px >= 1, "MarkerDetectionOptions::min_range_px must be >= 1");
  Require(merged_margin_px >= 0.0, "MarkerDetectionOptions::merged_margin_px must be >= 0");
  Require(near_blob_gap_px >= 0 && min_occluder_px >= 1,
          "MarkerDetectionOptions: near_blob_gap_px must be >= 0 and min_occluder_px >= 1");
  Require(occluder_ring_inner_px >= 1 && occluder_ring_outer_px >= occluder_ring_inner_px,
          "MarkerDetectionOptions: need 1 <= occluder_ring_inner_px <= occluder_ring_outer_px");
  Require(occluder_margin_mm >= 0.0, "MarkerDetectionOptions::occluder_margin_mm must be >= 0");
}

const char* ToString(BlobDropReason reason) {
  switch (reason) {
    case BlobDropReason::kImageBorder:
      return "image_border";
    case BlobDropReason::kMerged:
      return "merged";
  }
  return "unknown";
}

MarkerDetectionResult LocateMarkers(const AhatFrame& frame, const AhatCamera& camera,
                                    const MarkerDetectionOptions& options) {
  options.Check();
  Require(frame.ab.width() == camera.width() && frame.ab.height() == camera.height() &&
              frame.range_mm.width() == camera.width() &&
              frame.range_mm.height() == camera.height(),
          "LocateMarkers: frame and camera sizes differ");
  MarkerDetectionResult result;
  result.ab_threshold = AdaptiveThreshold(frame.ab, options);
  const BrightBlobs blobs = FindBrightBlobs(frame.ab, ToCounts(result.ab_threshold));
  result.blob_count = static_cast<int>(blobs.blobs.size());
  BlobMeasurer measurer(frame, camera, options, result.ab_threshold);
  for (const BrightBlob& blob : blobs.blobs) {
    if (std::optional<DetectedMarker> marker = measurer.Measure(blobs, blob, result)) {
      result.markers.push_back(*marker);
    }
  }
  return result;
}

}  // namespace tofnav
